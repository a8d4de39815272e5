#!/usr/bin/env python3
"""Plots a scene's asymptotic twist field with matplotlib: arrows of (s_x', s_y') over the plate, one
panel per orientation theta, coloured by the spin theta' (point parts: one panel, the velocity field),
with the fixed points (dots stable, crosses otherwise) and lines of fixed points found in it.

    PYTHONPATH=build/python python3 examples/plot_field.py scenes/fig4.json --grid 7 --out fig4.png
"""
import argparse
import math

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

import plate


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--grid", type=int, default=7, help="points per axis (default 7)")
    ap.add_argument("--panels", type=int, default=4, help="orientations shown (rigid parts)")
    ap.add_argument("--out", help="image file (default: a window)")
    args = ap.parse_args()

    scene = plate.load_scene(args.scene)
    for w in scene.warnings:
        print("warning:", w)
    field = plate.field(scene, grid=args.grid)
    fixed = plate.fixed_points(field)
    print(f"{scene.name}: {field.twist.shape[:3]} grid in {field.seconds:.3f} s on {field.threads} threads; "
          f"{fixed.sentence}")

    nth = len(field.theta)
    ks = [0] if scene.point_part else sorted({round(i * nth / args.panels) % nth for i in range(args.panels)})
    fig, axes = plt.subplots(1, len(ks), figsize=(3.6 * len(ks) + 1.2, 4.0), squeeze=False, constrained_layout=True)
    X, Y = np.meshgrid(field.x, field.y, indexing="ij")
    spin = field.twist[..., 2]
    lim = np.nanmax(np.abs(spin)) or 1.0
    for ax, k in zip(axes[0], ks):
        # each fixed point is shown in the panel of the nearest orientation
        u, v = field.twist[:, :, k, 0], field.twist[:, :, k, 1]
        colour = spin[:, :, k] if not scene.point_part else np.hypot(u, v)
        q = ax.quiver(X, Y, u, v, colour, cmap="coolwarm" if not scene.point_part else "viridis",
                      norm=matplotlib.colors.Normalize(-lim, lim) if not scene.point_part else None)
        for p in fixed.points:
            if scene.point_part or min(ks, key=lambda j: abs(math.remainder(p.q[2] - field.theta[j], 2 * math.pi))) == k:
                ax.plot(p.q[0], p.q[1], "o" if p.stability == "stable" else "x", color="k")
        for line in fixed.lines:
            pts = np.array(line.points)
            if scene.point_part or min(ks, key=lambda j: abs(math.remainder(pts[0, 2] - field.theta[j], 2 * math.pi))) == k:
                ax.plot(pts[:, 0], pts[:, 1], "-" if line.stability == "stable" else "--", color="k", lw=2)
        ax.set_aspect("equal")
        ax.set_xlabel("s_x [m]")
        if ax is axes[0][0]:
            ax.set_ylabel("s_y [m]")
        ax.set_title(scene.name if scene.point_part else f"{scene.name}: theta = {field.theta[k]:.2f} rad")
    fig.colorbar(q, ax=axes[0].tolist(), label="theta' [rad/s]" if not scene.point_part else "speed [m/s]")
    if args.out:
        fig.savefig(args.out, dpi=120)
        print("wrote", args.out)
    else:
        plt.show()


if __name__ == "__main__":
    main()
