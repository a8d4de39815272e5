"""Camera observations from Python: the command line's track to the bit, stroboscopic stamps, the
track file written and read back, and bad tracks refused with the file and the line."""
import os
import subprocess

import numpy as np
import pytest

import plate

SOURCE = os.environ.get("PLATE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("PLATE_EXE")
CAMERA = {"stroboscopic": {"phase": 0.25, "per_period": 2}, "noise": {"xy_mm": 0.1, "theta_mrad": 5},
          "latency_s": 0.002, "drop": 0.1, "seed": 4, "frame": "world"}


def scene_path(name):
    return os.path.join(SOURCE, "scenes", name + ".json")


@pytest.mark.skipif(not EXE, reason="PLATE_EXE (the program) not given")
def test_observe_gives_the_command_lines_track_to_the_bit(tmp_path):
    cam = tmp_path / "camera.json"
    cam.write_text(plate.parse_camera(str(CAMERA).replace("'", '"'), "<test>").to_json())
    out = tmp_path / "track.csv"
    cli = subprocess.run([EXE, "simulate", scene_path("fig4"), "--dynamics", "full", "--start", "0.03", "-0.02", "1",
                          "--time", "1", "--observe", str(cam), "--out", str(out)], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    scene = plate.load_scene(scene_path("fig4"))
    for camera in (CAMERA, str(cam), plate.load_camera(str(cam))):
        tk = plate.observe(scene, camera, start=(0.03, -0.02, 1.0), time=1.0)
        assert not tk.stop
        read = plate.read_track_csv(str(out))
        assert np.array_equal(tk.t, read.t) and np.array_equal(tk.q, read.q)
        assert read.scene_id == plate.scene_id(scene) == tk.scene_id
    # 40 stamps (two per period), about 10 % dropped
    assert 30 <= len(read) < 40


def test_stroboscopic_stamps_and_a_round_trip(tmp_path):
    scene = plate.load_scene(scene_path("fig1_point"))
    T = scene.period
    stamps = plate.frame_stamps(scene, {"stroboscopic": {"phase": 0.5}, "frame": "plate"}, 10 * T)
    assert np.array_equal(stamps, (np.arange(10) + 0.5) * T)
    tk = plate.observe(scene, CAMERA, start=(0.03, -0.02), time=0.5)
    assert tk.point and tk.frame == "world" and np.all(tk.q[:, 2] == 0)
    path = str(tmp_path / "point.csv")
    plate.write_track_csv(tk, path)
    back = plate.read_track_csv(path)
    assert np.array_equal(back.t, tk.t) and np.array_equal(back.q, tk.q) and back.camera.to_json() == tk.camera.to_json()
    plate.check_track_scene(back, scene)
    # A model's prediction at the recorded stamps: the camera without noise and drops; the track is off
    # it by the noise alone (sd 0.1 mm; 5 sd at most over these few frames).
    clean = dict(CAMERA, noise={}, drop=0)
    pred = plate.observe_at(scene, clean, start=(0.03, -0.02), stamps=tk.t)
    assert np.array_equal(pred.t, tk.t)
    assert 0 < np.abs(tk.q - pred.q).max() < 5e-4
    with pytest.raises(plate.InputError) as err:
        plate.check_track_scene(back, plate.load_scene(scene_path("fig4")))
    assert str(err.value).startswith(path + ":3: tracks from another scene")


def test_a_bad_track_names_its_file_and_line(tmp_path):
    scene = plate.load_scene(scene_path("fig4"))
    tk = plate.observe(scene, {"rate_hz": 100, "frame": "plate"}, start=(0.03, -0.02, 1.0), time=0.1)
    path = tmp_path / "t.csv"
    plate.write_track_csv(tk, str(path))
    lines = path.read_text().splitlines()
    lines[9] = lines[9].split(",")[0] + ",nan,0,0"     # frame 2, line 10
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(plate.InputError) as err:
        plate.read_track_csv(str(path))
    assert str(err.value).startswith(str(path) + ":10:2: s_x [m]: expected a finite number")
    with pytest.raises(plate.InputError) as err:
        plate.observe(scene, {"rate_hz": 100, "drop": 1.5, "frame": "plate"}, start=(0.03, -0.02, 1.0), time=0.1)
    assert "<dict>: drop: expected a probability in [0, 1)" in str(err.value)
