"""The hand from other sources: a WEART glove (the fake middleware), hand scripts, recordings."""

import pathlib

import pytest

import vrdeform

TESTS = pathlib.Path(__file__).resolve().parents[2] / "tests"


def test_a_glove_presses_the_liver_and_is_released():
    # The fake's glove closes its fingers over a second; over the liver's top the index presses.
    scene = vrdeform.build_scene(vrdeform.load_scene("liver"))
    news = []
    with vrdeform.FakeMiddleware(tracking="0 0 0 0\n1 0.9 0.9 0.9\n") as fake:
        summary = scene.run(steps=150, weart=fake.endpoint, glove_news=lambda line, error: news.append(line))
        commands = fake.commands()
        assert all(fake.force(f) == 0.0 for f in (vrdeform.Finger.THUMB, vrdeform.Finger.INDEX, vrdeform.Finger.MIDDLE))
    assert summary["steps"] == 150 and summary["newtons_max"]["index"] > 0.1
    assert "StartFromClient TrackType1" in commands and "StopFromClient" in commands
    assert any(c.startswith("force RIGHT INDEX 0.") and float(c.split()[-1]) > 0 for c in commands)
    for point in ("THUMB", "INDEX", "MIDDLE"):
        last = [c for c in commands if c.split()[:3] in (["force", "RIGHT", point], ["stopForce", "RIGHT", point])][-1]
        assert last.startswith("stopForce"), f"{point} left pressing: {last}"
    assert any("connected" in line for line in news)


def test_a_glove_that_is_not_there_is_reported_and_the_run_goes_on():
    scene = vrdeform.build_scene(vrdeform.load_scene("liver"))
    with vrdeform.FakeMiddleware() as fake:
        port = fake.port
    news = []
    summary = scene.run(steps=20, weart=f"127.0.0.1:{port}", glove_news=lambda line, error: news.append((line, error)))
    assert summary["steps"] == 20
    assert any(error and "cannot connect" in line for line, error in news), news
    with pytest.raises(vrdeform.Error, match="port"):
        scene.run(steps=1, weart="127.0.0.1:99999")


def test_a_hand_script_and_a_recording_drive_the_hand():
    scene = vrdeform.build_scene(vrdeform.load_scene("liver"))
    script = vrdeform.HandScript.load(TESTS / "cli" / "press_liver.hand")
    assert script.duration == pytest.approx(3.0)
    assert scene.run(steps=30, hand=script)["steps"] == 30
    with pytest.raises(vrdeform.Error, match="<python>:1"):
        vrdeform.HandScript.parse("not a hand script\n")
    recording = vrdeform.SessionRecording.load(TESTS / "fuzz_corpus" / "session_recording" / "ok_docs_example")
    assert recording.settings["scene"] == "poke liver"
    assert scene.run(hand=recording)["steps"] == len(recording)
    with pytest.raises(vrdeform.Error, match="hand: a callable"):
        scene.run(steps=1, hand=3)
