"""Scenes and the run loop from Python, against the command-line program on the same scene."""

import csv
import pathlib
import subprocess
import threading
import _thread

import numpy as np
import pytest

import vrdeform


def test_builtin_scenes_are_listed_and_an_unknown_one_is_named():
    assert {"liver", "jelly", "flag"} <= set(vrdeform.builtin_scenes())
    with pytest.raises(vrdeform.Error, match="liver"):
        vrdeform.load_scene("no-such-scene")


def test_a_run_matches_the_command_line_program_bit_for_bit(cli, tmp_path):
    steps = 150
    scene = vrdeform.build_scene(vrdeform.load_scene("liver"))  # small enough for one thread
    rows = []

    def record(step):
        h = step["haptics"]
        index = h.finger(vrdeform.Finger.INDEX)
        rows.append((h.paper, index.force, index.newtons, index.depth))

    summary = scene.run(steps=steps, callback=record)
    assert summary["ok"] and summary["steps"] == steps and len(rows) == steps
    c = scene.calibration
    assert c["force"] > 0 and c["depth"] > 0 and c["tau_contact"] > 0
    subprocess.run([str(cli), "run", "liver", "--steps", str(steps), "--out", str(tmp_path)],
                   check=True, capture_output=True)
    with open(tmp_path / "forces.csv") as f:
        table = list(csv.DictReader(f))
    expected = [(float(r["paper"]), float(r["index"]), float(r["index_N"]), float(r["index_depth_m"])) for r in table]
    assert len(expected) == steps
    dt = scene.spec.solver.time_step
    assert [int(r["step"]) for r in table] == list(range(1, steps + 1))
    assert all(float(r["time_s"]) == int(r["step"]) * dt for r in table)  # step x dt, exactly
    got = np.array(rows, dtype=np.float32)
    want = np.array(expected, dtype=np.float32)
    assert np.any(want[:, 2] > 0.5), "the poke reached the liver"
    assert 0.002 < want[:, 3].max() < 0.03, "the index went millimetres into the liver"
    np.testing.assert_array_equal(got, want)


def test_the_callback_can_stop_a_run_and_its_exceptions_arrive(tmp_path, monkeypatch):
    scene = vrdeform.build_scene(vrdeform.load_scene("jelly"))
    monkeypatch.chdir(tmp_path)
    summary = scene.run(steps=100, callback=lambda s: s["step"] < 9)
    assert summary["steps"] == 10
    assert summary["files"] == [] and not any(tmp_path.iterdir()), "no out: no files"

    def fail(step):
        raise ValueError("from the callback")

    with pytest.raises(ValueError, match="from the callback"):
        scene.run(steps=10, callback=fail)


def test_a_python_hand_presses_the_body():
    spec = vrdeform.load_scene("jelly")
    scene = vrdeform.build_scene(spec)
    body = scene.bodies[spec.bodies[0]]
    p = np.array(scene.world.positions(body))
    x, height, z = p[np.argmax(p[:, 1])]  # above the highest particle
    newtons = []

    def hand(step, time):
        if step >= 120:
            return None
        depth = min(step / 60, 1.0) * 0.01
        tips = np.full((5, 3), 10.0, dtype=np.float32)  # the other fingers far away
        tips[1] = (x, height + 0.009 - depth, z)  # the index fingertip (radius 9 mm) presses 1 cm
        return tips

    summary = scene.run(steps=200, hand=hand, callback=lambda s: newtons.append(
        s["haptics"].finger(vrdeform.Finger.INDEX).newtons))
    assert summary["steps"] == 121  # the hand ended the run: the step it returned None in holds it still
    assert max(newtons) > 0.05
    assert newtons[119] > newtons[30] > 0  # pressing deeper pushes harder

    with pytest.raises(vrdeform.Error, match=r"\(5, 3\)"):
        scene.run(steps=5, hand=lambda step, time: np.zeros(3))


def test_ctrl_c_stops_a_long_run():
    scene = vrdeform.build_scene(vrdeform.load_scene("liver"))
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        scene.run(steps=10_000_000)
    timer.join()


def test_ctrl_c_stops_settling():
    spec = vrdeform.load_scene("liver")
    spec.settle = 300.0
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        vrdeform.build_scene(spec)
    timer.join()


def test_scene_of_mesh_gives_the_scene_files_defaults():
    meshes = pathlib.Path(vrdeform.load_scene("liver").source).parent.parent / "data" / "meshes"
    spec = vrdeform.scene_of_mesh(meshes / "liver_coarse.obj", scale=0.001)
    assert spec.name == "liver_coarse" and spec.bodies == ["body1"]
    assert spec.solver.substeps == 8 and spec.settle_to_rest and spec.hand_enabled
    spec.settle, spec.settle_to_rest, spec.calibrate = 0.5, False, False
    scene = vrdeform.build_scene(spec)
    summary = scene.run(steps=5)
    height = np.array(scene.world.positions(scene.bodies["body1"]))[:, 1].max()
    assert summary["ok"] and 0.1 < height < 0.2  # 17 cm: the millimetres scaled
    with pytest.raises(vrdeform.Error, match="scale must be a positive number"):
        vrdeform.scene_of_mesh(meshes / "liver_coarse.obj", scale=0.0)
    with pytest.raises(vrdeform.Error, match="no such file"):
        vrdeform.scene_of_mesh(meshes / "nope.obj")


def test_a_scene_of_a_mesh_alone(tmp_path):
    meshes = pathlib.Path(vrdeform.load_scene("liver").source).parent.parent / "data" / "meshes"
    text = """
format = 1
name = "tiny"
settle = 0.2
seconds = 0.1
[[body]]
mesh = "sphere_coarse.obj"
scale = 0.03
[hand]
enabled = false
"""
    spec = vrdeform.parse_scene(text, base_dir=meshes)
    spec.calibrate = False
    scene = vrdeform.build_scene(spec)
    summary = scene.run(out=tmp_path)
    assert summary["ok"] and (tmp_path / "summary.json").exists()
    with pytest.raises(vrdeform.Error, match="<python>"):
        vrdeform.parse_scene("format = 1\n[[body]]\nmesh = 3\n")
