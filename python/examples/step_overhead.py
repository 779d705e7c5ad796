"""What calling World.step() from Python costs on top of the step itself.

    PYTHONPATH=build/release/python python3 python/examples/step_overhead.py [steps rounds]

Each world stepped n times from a Python loop and n times in one call (World.steps, a C++ loop),
alternating, on one thread: the paper-sized body (the liver scene's, 738 tets at 8 x 5) and a
cube of five tets, whose steps are short enough to show the binding's share plainly. Run it on a
quiet machine.
"""

import statistics
import sys
import time

import numpy as np

import vrdeform


def liver():
    spec = vrdeform.load_scene("liver")
    spec.hand_enabled = False
    spec.calibrate = False
    spec.solver.threads = 1
    return vrdeform.build_scene(spec).world


def cube():
    v = np.array([[x, y, z] for x in (0, 0.01) for y in (0, 0.01) for z in (0, 0.01)], dtype=np.float32)
    tets = []
    for t in ([0, 1, 2, 4], [3, 2, 1, 7], [5, 1, 4, 7], [6, 4, 2, 7], [1, 2, 4, 7]):
        a, b, c, d = (v[i] for i in t)
        tets.append(t if np.dot(b - a, np.cross(c - a, d - a)) > 0 else [t[0], t[2], t[1], t[3]])
    world = vrdeform.World()
    world.add_soft_body(vrdeform.TetMesh(v, tets))
    world.add_collider(vrdeform.Collider.plane())
    return world


def timings(world, n, rounds):
    python_loop, cpp_loop = [], []
    for _ in range(rounds):
        start = time.perf_counter()
        for _ in range(n):
            world.step()
        python_loop.append((time.perf_counter() - start) / n)
        start = time.perf_counter()
        world.steps(n)
        cpp_loop.append((time.perf_counter() - start) / n)
    return statistics.median(cpp_loop) * 1e6, statistics.median(python_loop) * 1e6


def main(n=2000, rounds=7):
    print(f"us a step, median of {rounds} rounds of {n} steps")
    print(f"{'world':34}{'C++ loop':>10}{'Python loop':>13}{'Python adds':>13}")
    for name, make in (("liver, 738 tets, 8 x 5", liver), ("cube, 5 tets, 1 x 5", cube)):
        cpp_us, py_us = timings(make(), n, rounds)
        print(f"{name:34}{cpp_us:>10.2f}{py_us:>13.2f}{py_us - cpp_us:>13.2f}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:]))
