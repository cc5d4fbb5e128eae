//! Deterministic fuzzing of the profile-file readers (issue 8).
//!
//! cargo-fuzz needs a nightly toolchain (libFuzzer, `-Z sanitizer`), and this project
//! builds with stable only, so this is a libFuzzer-free harness: a seeded xorshift
//! generator produces random byte strings and token-level mutations of valid SIMPACK
//! and two-column files, fed to [`parse_simpack`], [`parse_two_column`] and (when they
//! parse) [`SimpackProfile::to_profile`] / [`Profile::from_points`]. Every input must
//! return `Ok` or a [`ProfileError`] whose message names the file (and line for parse
//! errors) — never panic. The number of inputs is `PROFILE_FUZZ_CASES` (default 100 000;
//! the seed `PROFILE_FUZZ_SEED`), so a longer campaign is
//! `PROFILE_FUZZ_CASES=10000000 cargo test --release -p rail-mbs --test profile_fuzz`.

use std::panic::{AssertUnwindSafe, catch_unwind};

use rail_mbs::profile::io::{parse_simpack, parse_two_column};
use rail_mbs::profile::{Profile, ProfileError};

const SIMPACK: &str = "! header\n  header.begin\n    version = 1\n    type = 0\n  header.end\n  spline.begin\n    \
comment = 'test rail'\n    units.len.f = 1000\n    shift.y = 0.5\n    mirror.y = 0\n    bound.y.min = -40\n    \
bound.y.max = 40\n    point.begin\n -40 5.1\n -20 1.2 1\n 0 0\n 20 1.2\n 40 5.1\n    point.end\n  spline.end\n";

const TWO_COLUMN: &str = "# y z\n-0.04, 0.0051\n-0.02; 0.0012\n0 0 1\n0.02 0.0012\n// end\n0.04 0.0051\n";

const TOKENS: &[&str] = &[
    "\n",
    " ",
    "=",
    "!",
    "'",
    "#",
    ",",
    ";",
    "-",
    ".",
    "e",
    "0",
    "1",
    "nan",
    "inf",
    "-inf",
    "1e400",
    "1e-400",
    "point.begin",
    "point.end",
    "header.begin",
    "header.end",
    "spline.begin",
    "spline.end",
    "type = 1",
    "type = 7",
    "units.len.f = 0",
    "units.len.f = -1",
    "mirror.z = 1",
    "rotate = 1",
    "bound.y.min = 1e308",
    "shift.y = 1e308",
    "\u{0}",
    "\u{feff}",
    "é",
    "\r\n",
    "9999999999999999999999",
];

/// xorshift64* — deterministic and dependency-free.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

/// Random bytes (decoded lossily) or 1–8 token-level mutations of a valid file.
fn generate(rng: &mut Rng) -> String {
    match rng.below(5) {
        0 => {
            let len = rng.below(300);
            let bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
            String::from_utf8_lossy(&bytes).into_owned()
        }
        k => {
            let mut s: Vec<char> = if k % 2 == 0 { SIMPACK } else { TWO_COLUMN }.chars().collect();
            for _ in 0..1 + rng.below(8) {
                let i = rng.below(s.len() + 1);
                match rng.below(4) {
                    0 => {
                        let end = (i + 1 + rng.below(12)).min(s.len());
                        s.drain(i.min(end)..end);
                    }
                    1 => {
                        let tok = TOKENS[rng.below(TOKENS.len())];
                        s.splice(i..i, tok.chars());
                    }
                    2 if i < s.len() => s[i] = TOKENS[rng.below(TOKENS.len())].chars().next().unwrap_or('x'),
                    _ => {
                        // Duplicate a slice (repeated blocks, long lines).
                        let end = (i + rng.below(40)).min(s.len());
                        let dup: Vec<char> = s[i.min(end)..end].to_vec();
                        s.splice(i..i, dup);
                    }
                }
            }
            s.into_iter().collect()
        }
    }
}

fn check_error(e: &ProfileError, label: &str, input: &str) {
    let msg = e.to_string();
    assert!(!msg.is_empty(), "empty error message for {input:?}");
    if let ProfileError::Parse { file, line, .. } = e {
        assert_eq!(file, label, "parse error names another file: {msg}");
        assert!(*line <= input.lines().count().max(1), "line {line} beyond the input: {msg}");
    }
}

fn feed(input: &str) {
    match parse_simpack(input, "fuzz.prr") {
        Ok(p) => {
            assert!(p.raw_points.iter().all(|(y, z)| y.is_finite() && z.is_finite()), "{input:?}");
            if let Ok(profile) = p.to_profile() {
                let (y0, y1) = profile.y_range();
                assert!(y0.is_finite() && y1.is_finite() && y0 <= y1, "{input:?}");
            }
        }
        Err(e) => check_error(&e, "fuzz.prr", input),
    }
    match parse_two_column(input, "fuzz.txt") {
        Ok(pts) => {
            assert!(pts.len() >= 2 && pts.iter().all(|(y, z)| y.is_finite() && z.is_finite()), "{input:?}");
            let _ = Profile::from_points("fuzz", &pts);
        }
        Err(e) => check_error(&e, "fuzz.txt", input),
    }
}

#[test]
fn random_and_mutated_profile_files_never_panic_and_errors_name_file_and_line() {
    let cases = env_usize("PROFILE_FUZZ_CASES", 100_000);
    let mut rng = Rng(env_usize("PROFILE_FUZZ_SEED", 0x5EED_F11E) as u64 | 1);
    let (mut ok, mut err) = (0usize, 0usize);
    for case in 0..cases {
        let input = generate(&mut rng);
        if catch_unwind(AssertUnwindSafe(|| feed(&input))).is_err() {
            panic!("case {case} panicked; input: {input:?}");
        }
        if parse_simpack(&input, "f").is_ok() {
            ok += 1;
        } else {
            err += 1;
        }
    }
    println!("{cases} inputs: {ok} SIMPACK files parsed, {err} rejected with an error");
    // The mutations keep a fair share of files valid (so to_profile is exercised too).
    assert!(ok > cases / 50 && err > cases / 50, "ok {ok}, err {err}");
}

#[test]
fn the_seed_files_are_valid() {
    let p = parse_simpack(SIMPACK, "seed.prr").unwrap();
    assert_eq!(p.raw_points.len(), 5);
    p.to_profile().unwrap();
    assert_eq!(parse_two_column(TWO_COLUMN, "seed.txt").unwrap().len(), 5);
}

#[test]
fn binary_profile_files_are_parse_errors_naming_the_line() {
    let path = std::env::temp_dir().join(format!("railslosh-fuzz-{}.prr", std::process::id()));
    std::fs::write(&path, b"header.begin\n type = 0\n\xff\xfe junk\n").unwrap();
    for result in
        [rail_mbs::profile::read_simpack(&path).map(|_| ()), rail_mbs::profile::read_two_column(&path).map(|_| ())]
    {
        match result {
            Err(ProfileError::Parse { line, message, .. }) => {
                assert_eq!(line, 3, "{message}");
                assert!(message.contains("not UTF-8") && message.contains("0xff"), "{message}");
            }
            other => panic!("expected a parse error, got {other:?}"),
        }
    }
    std::fs::remove_file(&path).unwrap();
}
