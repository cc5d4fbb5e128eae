"""SwRI elliptical tank (seed 003 appendix C), half full of water, under the Fluent case's
lateral acceleration of 0.3 g for 0.5 s: the six load components of the fluid on the tank.

Usage: python scripts/swri_lateral_loads.py [--out DIR] [--quick]
Writes DIR/swri_lateral_loads.csv and, if matplotlib is installed, DIR/swri_lateral_loads.png.
"""

import argparse
import pathlib

import numpy as np

import railslosh as rs


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--out", default="out")
    p.add_argument("--quick", action="store_true", help="coarser mesh, shorter run")
    a = p.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    # an even count along the length, across the plane x = 0 that the tank and the pulse are
    # mirror-symmetric in: with 3 (or 5) elements the loads that symmetry makes zero (F_x, M_y, M_z)
    # grow from round-off to a few newtons by 2 s (docs/validation.md, "The SwRI lateral run's
    # growing mode")
    counts = (2, 4, 2) if a.quick else (4, 6, 3)
    mesh = rs.mesh.elliptic_cylinder(n_length=counts[0], n_width=counts[1], n_height=counts[2])
    depth = mesh.free_surface_z + rs.mesh.SWRI_SEMI_AXIS_Z
    tank = rs.slosh.TankGeometry.elliptic(rs.mesh.SWRI_LENGTH, rs.mesh.SWRI_SEMI_AXIS_Y, rs.mesh.SWRI_SEMI_AXIS_Z)
    motion = rs.slosh.Motion().pulse("y", 0.3 * rs.constants.GRAVITY, 0.0, 0.5)
    # the SwRI scenes' quadrature (examples/scenes/swri_*.toml): with 3^3 force points and 3x3
    # contact points the field of these elements folds between the points (docs/validation.md);
    # the bump scenes' walls and stabilization: with the library's walls the loads after the pulse
    # carry wall chatter (F_x up to 15 N and M_y, M_z up to 1.3 N m, which symmetry makes zero,
    # against F_y +-40 N); with these (on 3x6x3), F_x 3.7 N, M_y 0.27, M_z 0.43 N m (docs/validation.md,
    # "SwRI peak loads")
    water = rs.fluids.water(
        depth=depth,
        shear_stabilization=rs.fluids.default_shear_stabilization(rs.fluids.LIQUIDS["water"][0], depth / counts[2]),
    )
    res = rs.slosh.run(
        mesh,
        water,
        tank,
        motion,
        t_end=1.5 if a.quick else 3.0,
        step=0.004,
        viscous_points=4,
        penalty_points=4,
        contact_points_per_edge=5,
        wall_damping_ratio=1.0,
        wall_adhesion=4.0,
    )
    data = np.column_stack([res["t"], res["force_tank"], res["moment_tank"]])
    header = "t_s,Fx_N,Fy_N,Fz_N,Mx_Nm,My_Nm,Mz_Nm"
    np.savetxt(out / "swri_lateral_loads.csv", data, delimiter=",", header=header, comments="")
    print(f"wrote {out / 'swri_lateral_loads.csv'} ({len(res['t'])} rows, {res['stats']['steps']} steps)")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no PNG (pip install matplotlib)")
        return
    fig, axes = plt.subplots(2, 3, figsize=(12, 6), sharex=True)
    names = header.split(",")[1:]
    for k, ax in enumerate(axes.flat):
        ax.plot(res["t"], data[:, k + 1])
        ax.set_title(names[k].replace("_", " (") + ")")
        ax.grid(True, alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    fig.suptitle(
        "SwRI elliptical tank, half full of water, 0.3 g lateral for 0.5 s: fluid load on the tank (tank axes)"
    )
    fig.tight_layout()
    fig.savefig(out / "swri_lateral_loads.png", dpi=120)
    print(f"wrote {out / 'swri_lateral_loads.png'}")


if __name__ == "__main__":
    main()
