"""Poke the liver with the index fingertip and plot the force against the indentation depth.

    PYTHONPATH=build/release/python python3 python/examples/poke_liver.py [out.png]

The fingertip comes down above the liver's highest point, presses 12 mm over two seconds, holds,
and lifts; the plot shows the force in newtons and the glove's normalised value against depth.
"""

import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import vrdeform  # noqa: E402

RADIUS = 0.009  # the G1 hand's fingertip radius (m)
DEPTH = 0.012


def main(out="poke_liver.png"):
    spec = vrdeform.load_scene("liver")
    scene = vrdeform.build_scene(spec)
    p = np.array(scene.world.positions(scene.bodies["liver"]))
    x, top, z = p[np.argmax(p[:, 1])]
    dt = spec.solver.time_step
    press, hold = int(2.0 / dt), int(1.0 / dt)

    def depth_at(step):
        u = min(step / press, 1.0)
        return DEPTH * (10 * u**3 - 15 * u**4 + 6 * u**5) if step < press + hold else None  # minimum jerk

    def hand(step, time):
        d = depth_at(step)
        if d is None:
            return None
        tips = np.full((5, 3), 10.0, dtype=np.float32)  # the other fingers far above
        tips[vrdeform.Finger.INDEX.value] = (x, top + RADIUS - d, z)
        return tips

    depth, newtons, force = [], [], []

    def record(step):
        d = depth_at(step["step"])
        if d is not None:
            f = step["haptics"].finger(vrdeform.Finger.INDEX)
            depth.append(d * 1000), newtons.append(f.newtons), force.append(f.force)

    summary = scene.run(steps=press + hold + 1, hand=hand, callback=record)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(depth, newtons, label="force (N)")
    ax.set_xlabel("indentation (mm)")
    ax.set_ylabel("force (N)")
    twin = ax.twinx()
    twin.plot(depth, force, color="tab:orange", label="glove value")
    twin.set_ylabel("normalised force")
    ax.set_title("liver, index fingertip")
    fig.legend(loc="upper left", bbox_to_anchor=(0.12, 0.9))
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"{summary['steps']} steps; peak {max(newtons):.2f} N at {max(depth):.1f} mm; plot in {out}")


if __name__ == "__main__":
    main(*sys.argv[1:])
