import sys

from railslosh.cli import main

sys.exit(main())
