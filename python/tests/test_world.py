"""The engine from Python: arrays, stepping, errors, the GIL."""

import gc
import threading
import time

import numpy as np
import pytest

import vrdeform


def soft_material():
    return vrdeform.Material(vrdeform.ElasticModuli(youngs=5e4, poisson=0.3, density=1000.0))


def world_with_cube(cube, substeps=4):
    s = vrdeform.SolverSettings()
    s.substeps = substeps
    w = vrdeform.World(s)
    body = w.add_soft_body(cube, soft_material(), translation=(0.0, 1.0, 0.0))
    return w, body


def test_arrays_have_the_right_shapes_dtypes_and_are_read_only(cube):
    w, body = world_with_cube(cube)
    p, v = w.positions(body), w.velocities(body)
    assert p.shape == (8, 3) and v.shape == (8, 3)
    assert p.dtype == np.float32 and v.dtype == np.float32
    assert not p.flags.writeable and not v.flags.writeable
    with pytest.raises(ValueError):
        p[0, 0] = 1.0
    np.testing.assert_allclose(p, cube.vertices + np.array([0, 1, 0], np.float32), atol=1e-6)
    m = w.multipliers(body)
    assert m["volume"].shape == (5,) and m["strain"].shape == (6, 5) and m["shape_matching"].shape == (8, 3)
    assert all(not a.flags.writeable for a in m.values())


def test_views_show_the_live_state_and_free_fall_is_exact(cube):
    # Free fall of a body at rest for N substeps of h (symplectic Euler, no constraint violated):
    # every particle moves by -g h^2 N (N + 1) / 2.
    w, body = world_with_cube(cube, substeps=4)
    p = w.positions(body)
    start = np.array(p)
    steps = 30
    w.steps(steps)
    h = w.settings.substep_size
    n = steps * w.settings.substeps
    drop = 9.81 * h * h * n * (n + 1) / 2
    np.testing.assert_allclose(p[:, 1] - start[:, 1], -drop, rtol=1e-4)
    np.testing.assert_allclose(p[:, [0, 2]], start[:, [0, 2]], atol=1e-6)
    np.testing.assert_allclose(w.velocities(body)[:, 1], -9.81 * h * n, rtol=1e-4)


def test_a_view_keeps_its_world_alive(cube):
    w, body = world_with_cube(cube)
    p = w.positions(body)
    expected = np.array(p)
    del w
    gc.collect()
    np.testing.assert_array_equal(p, expected)


def test_no_body_is_added_while_views_are_alive(cube):
    w, body = world_with_cube(cube)
    p = w.positions(body)
    with pytest.raises(vrdeform.Error, match="view"):
        w.add_soft_body(cube, soft_material())
    del p
    gc.collect()
    assert w.add_soft_body(cube, soft_material()) == 1
    assert w.body_count == 2


def test_writes_are_checked(cube):
    w, body = world_with_cube(cube)
    moved = np.array(w.positions(body)) + [0.1, 0, 0]
    w.set_positions(body, moved)
    np.testing.assert_allclose(w.positions(body), moved, atol=1e-6)
    with pytest.raises(vrdeform.Error, match=r"shape \(8, 3\)"):
        w.set_positions(body, np.zeros((7, 3)))
    bad = moved.copy()
    bad[3, 1] = np.nan
    with pytest.raises(vrdeform.Error, match="finite"):
        w.set_velocities(body, bad)
    with pytest.raises(vrdeform.Error, match="body 5 does not exist"):
        w.positions(5)


def test_bad_meshes_and_settings_raise(cube):
    with pytest.raises(vrdeform.Error, match="refers to vertex 9"):
        vrdeform.TetMesh(np.zeros((4, 3)), [[0, 1, 2, 9]])
    with pytest.raises(vrdeform.Error, match=r"shape \(n, 3\)"):
        vrdeform.TetMesh(np.zeros((4, 2)), [[0, 1, 2, 3]])
    with pytest.raises(vrdeform.Error, match="degenerate"):
        vrdeform.TetMesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float32), [[0, 1, 2, 3]])
    w = vrdeform.World()
    s = vrdeform.SolverSettings()
    s.substeps = 0
    with pytest.raises(vrdeform.Error, match="substeps"):
        vrdeform.World(s)
    with pytest.raises(vrdeform.Error, match="rotation"):
        w.add_soft_body(cube, rotation=(0, 0, 0, 0))


def test_a_fingertip_pressing_a_block_on_the_ground_pushes_with_its_weight_and_more(cube):
    s = vrdeform.SolverSettings()
    s.substeps = 8
    s.warm_start = True
    w = vrdeform.World(s)
    body = w.add_soft_body(cube, soft_material())
    w.add_collider(vrdeform.Collider.plane())
    w.steps(60)
    top = float(np.max(w.positions(body)[:, 1]))
    tip = w.add_fingertip((0.005, top + 0.004, 0.005), 0.004, mode=vrdeform.FingertipContactMode.TRIANGLES)
    w.move_fingertip(tip, (0.005, top + 0.003, 0.005))
    w.steps(30)
    f = w.fingertip_force(tip)
    assert f[1] < 0  # pushes the block down
    forces = w.constraint_forces(body)
    assert forces.shape == (8, 3)
    assert np.isfinite(forces).all()


def test_step_releases_the_gil():
    # A body big enough to take a while per step; another Python thread must run meanwhile.
    g = np.mgrid[0:13, 0:13, 0:13].reshape(3, -1).T.astype(np.float32) * 0.01
    index = lambda x, y, z: (x * 13 + y) * 13 + z  # noqa: E731
    tets = []
    for x in range(12):
        for y in range(12):
            for z in range(12):
                c = [index(x + i, y + j, z + k) for i in (0, 1) for j in (0, 1) for k in (0, 1)]
                for t in ([0, 1, 2, 4], [3, 2, 1, 7], [5, 1, 4, 7], [6, 4, 2, 7], [1, 2, 4, 7]):
                    q = [c[i] for i in t]
                    a, b, cc, d = (g[i] for i in q)
                    tets.append(q if np.dot(b - a, np.cross(cc - a, d - a)) > 0 else [q[0], q[2], q[1], q[3]])
    s = vrdeform.SolverSettings()
    s.substeps = 8
    s.threads = 1
    w = vrdeform.World(s)
    w.add_soft_body(vrdeform.TetMesh(g, tets), soft_material())
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1
            time.sleep(0)

    t = threading.Thread(target=count)
    t.start()
    start = ticks
    for _ in range(5):
        w.step()
    during = ticks - start
    done.set()
    t.join()
    assert during > 10, f"the other thread ran {during} times while step() ran"


def test_step_report_and_residuals(cube):
    s = vrdeform.SolverSettings()
    s.measure_residuals = True
    w = vrdeform.World(s)
    w.add_soft_body(cube, soft_material())
    w.step()
    r = w.last_step
    assert r.step == 0 and r.iterations == s.iterations * s.substeps
    assert "strain_volume" in r.residuals and all(np.isfinite(v).all() for v in r.residuals.values())
    assert set(r.times_ms) >= {"predict", "finalise"}


def test_bodies_touch_each_other_and_the_contact_carries_the_weight(cube):
    s = vrdeform.SolverSettings()
    s.substeps = 8
    s.iterations = 10
    s.warm_start = True
    s.linear_damping = 5.0
    w = vrdeform.World(s)
    lower = w.add_soft_body(cube, soft_material())
    upper = w.add_soft_body(cube, soft_material(), translation=(0.0, 0.0125, 0.0))
    w.add_collider(vrdeform.Collider.plane())
    settings = w.body_contact(upper)
    assert settings.bodies and not settings.self and settings.thickness == pytest.approx(0.001)
    settings.static_friction = 0.8
    w.set_body_contact(upper, settings)
    assert w.body_contact(upper).static_friction == pytest.approx(0.8)
    for _ in range(90):
        w.step()
    weight = 1000.0 * 1e-6 * 9.81  # a 1 cm cube of 1000 kg/m^3
    assert w.last_step.body_contacts > 0
    assert w.last_step.deepest_penetration <= 0.001
    assert w.body_contact_force(upper, lower)[1] == pytest.approx(weight, rel=0.05)
    assert w.positions(upper)[:, 1].min() > w.positions(lower)[:, 1].max()
    with pytest.raises(vrdeform.Error, match="thickness"):
        w.set_body_contact(upper, vrdeform.BodyContactSettings(thickness=-1.0))
    # Switched off, the pair passes through each other: the upper cube falls into the lower.
    w.set_pair_contact(lower, upper, False)
    for _ in range(30):
        w.step()
    assert w.positions(upper)[:, 1].min() < w.positions(lower)[:, 1].max()
