"""Closed-loop control from Python: plate.control gives the command line's run to the bit, a Python
policy's still plate and fixed transport move the part as physics says, plate.ControlEnv steps the same
loop, and a policy's bad answers are refused by name."""
import csv
import json
import math
import os
import subprocess

import numpy as np
import pytest

import plate

SOURCE = os.environ.get("PLATE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("PLATE_EXE")
SCENE = os.path.join(SOURCE, "scenes", "fig1_point.json")
LIBRARY = os.path.join(SOURCE, "scenes", "control", "fig1_point", "library.json")
# The truth and camera: friction 20 % below the model's, 3 % / 0.03 rad tracking errors drawn
# every period; world-frame frames with 0.1 mm noise, one period late, 10 % dropped.
TRUTH = {"friction_scale": 0.8, "uncertainty": {"seed": 7, "amplitude": {"spread": 0.03}, "phase": {"spread": 0.03}}}
CAMERA = {"stroboscopic": {"phase": 0}, "noise": {"xy_mm": 0.1}, "latency_s": 0.05, "drop": 0.1, "seed": 3,
          "frame": "world"}
GOAL = (0.02, -0.01)


def scene():
    return plate.load_scene(SCENE)


@pytest.mark.skipif(not EXE, reason="PLATE_EXE (the program) not given")
@pytest.mark.parametrize("policy", ["library", "mpc"])
def test_the_library_and_mpc_policies_give_the_command_lines_run_to_the_bit(tmp_path, policy):
    (tmp_path / "truth.json").write_text(json.dumps(TRUTH))
    (tmp_path / "camera.json").write_text(json.dumps(CAMERA))
    out = tmp_path / "run.csv"
    cli = subprocess.run([EXE, "control", SCENE, "--goal", "0.02", "-0.01", "--start", "-0.04", "0.03", "--policy",
                          policy, "--library", LIBRARY, "--camera", str(tmp_path / "camera.json"), "--truth",
                          str(tmp_path / "truth.json"), "--time", "3", "--out", str(out)], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    expected = json.loads(cli.stdout)
    run = plate.control(scene(), GOAL, library=LIBRARY, truth=TRUTH, camera=CAMERA, start=(-0.04, 0.03), time=3.0,
                        policy=policy)
    wall = {"decision_mean_s", "decision_max_s", "decision_p99_s"}   # wall-clock times differ run to run
    assert {k: v for k, v in run.summary.items() if k not in wall} == {k: v for k, v in expected.items() if k not in wall}
    assert run.summary["reached"] and run.reached and run.summary["periods"] == 60
    with open(out) as f:
        rows = list(csv.reader(f))[1:]
    assert len(rows) == len(run.t) == 61
    # t, observed s_x s_y, true x y, in shortest round-trip digits; no observation yet: an empty cell
    cells = np.array([[float(c) if c else math.nan for c in r[:5]] for r in rows])
    assert np.array_equal(cells[:, 0], run.t)
    assert np.array_equal(cells[:, 1:3], run.observed[:, :2], equal_nan=True)
    assert np.array_equal(cells[:, 3:5], run.truth[:, :2])
    assert [r[5] for r in rows[:-1]] == [run.motions[m] for m in run.motion[:-1]]
    assert f"plate.ControlRun policy {policy}: 60 periods, goal reached" in repr(run)
    if policy == "mpc":   # the correction changes the run: without it the rows differ
        plain = plate.control(scene(), GOAL, library=LIBRARY, truth=TRUTH, camera=CAMERA, start=(-0.04, 0.03), time=3.0,
                              policy=policy, correction=False)
        assert not np.array_equal(plain.truth, run.truth)
    else:   # (the mpc's options are refused on the library policy, as the command line refuses them)
        with pytest.raises(ValueError, match="switch_cost and correction are the mpc policy's"):
            plate.control(scene(), GOAL, library=LIBRARY, time=0.1, policy=policy, correction=False)


def test_a_python_policy_on_the_still_plate_leaves_the_part_where_it_is():
    # A plate at rest: nothing pushes the part, which rests where it was put (the world and the plate frame
    # coincide on a still plate). Measured: not a bit moves; 1e-15 m allows rounding.
    seen = []

    def still(obs):
        seen.append(obs)
        return obs["motions"].index("still")

    run = plate.control(scene(), GOAL, library=LIBRARY, start=(0.01, -0.02), time=1.0, policy=still)
    assert len(seen) == 20 and [o["period"] for o in seen] == list(range(20))
    assert seen[0]["t"] == 0 and math.isclose(seen[5]["t"], 5 * scene().period)
    assert np.abs(run.truth[:, :2] - [0.01, -0.02]).max() <= 1e-15
    assert np.all(run.motion[:-1] == seen[0]["motions"].index("still")) and run.summary["policy"] == "python"


def test_a_python_policy_holding_a_transport_moves_the_part_at_its_twist():
    # From period 10 on the part is on the transport's cycle (from rest it takes a few periods): the last 40
    # periods move it by 40 T xi, xi the cycle's twist (plate.twist of the motion's scene; a plate that only
    # translates gives a point part that twist everywhere). Perfect truth and camera. Measured: off by
    # 6.3e-10 m of 0.08 m (from period 5, 2e-6 m: not yet on the cycle); tolerance 2e-9 m. The same motion
    # as a list of harmonics (the policy's own motion) moves the part the same.
    motion = plate.load_scene(os.path.join(SOURCE, "scenes", "control", "fig1_point", "e_fast.json"))
    xi = plate.twist(motion, at=(0.0, 0.0), tol=1e-10).twist[:2]
    T = scene().period
    for policy in ("e_fast", motion.harmonics):
        run = plate.control(scene(), GOAL, library=LIBRARY, start=(-0.01, 0.01), time=50 * T, policy=lambda obs: policy)
        moved = run.truth[50, :2] - run.truth[10, :2]
        assert np.abs(moved - 40 * T * xi).max() < 2e-9, (moved, 40 * T * xi)
        assert np.linalg.norm(moved) > 0.05
    assert np.all(run.motion[:-1] == -1)   # the policy's own motion


def test_the_env_steps_the_same_loop_and_reset_reproduces():
    # The actions a Python policy took, replayed through ControlEnv: the same true trajectory to the bit and
    # the same observations; one step = one period; reward = minus the world distance to the goal.
    own = plate.load_scene(os.path.join(SOURCE, "scenes", "control", "fig1_point", "s_mid.json")).harmonics
    actions = ["e_fast", 3, own, "still", "sw_mid"] * 4
    observed = []

    def replay(obs):
        observed.append(obs)
        return actions[obs["period"]]

    kw = dict(library=LIBRARY, truth=TRUTH, camera=CAMERA, start=(-0.01, 0.01), seed=5)
    T = scene().period
    run = plate.control(scene(), GOAL, time=len(actions) * T, policy=replay, **kw)
    env = plate.ControlEnv(scene(), GOAL, time=len(actions) * T, **kw)

    def episode(seed=None):
        obs, steps = env.reset(seed=seed), []
        for a in actions:
            steps.append((obs, *env.step(a)))
            obs = steps[-1][1]
        return steps

    steps = episode()
    assert env.periods == len(actions)
    for (obs, _, reward, terminated, truncated, info), seen in zip(steps, observed):
        assert obs["period"] == seen["period"] and obs["seen"] == seen["seen"]
        if obs["seen"]:
            assert np.array_equal(obs["observed"], seen["observed"])
        assert reward == -math.hypot(info["true"][0] - GOAL[0], info["true"][1] - GOAL[1])
        assert terminated == (-reward <= 1e-3)
    assert steps[-1][4] or steps[-1][3]   # the last period: truncated (or within tolerance)
    assert not any(s[4] for s in steps[:-1])
    replayed = env.run()
    assert np.array_equal(replayed.truth, run.truth) and np.array_equal(replayed.t, run.t)
    assert np.array_equal(replayed.observed, run.observed, equal_nan=True)
    assert np.array_equal(replayed.motion, run.motion)
    with pytest.raises(RuntimeError, match="call reset"):
        env.step("still")
    again = [s[5]["true"] for s in episode(seed=5)]
    assert all(np.array_equal(a, s[5]["true"]) for a, s in zip(again, steps))
    other = [s[5]["true"] for s in episode(seed=6)]   # another draw of the truth and the camera
    assert not all(np.array_equal(a, b) for a, b in zip(again, other))


def test_a_bad_answer_raises_ValueError_naming_it():
    sc = scene()
    d = plate.load_scene(os.path.join(SOURCE, "scenes", "control", "fig1_point", "e_fast.json")).to_dict()
    d["plate"]["period"] = 0.04
    slower = plate.scene_from_dict(d)
    cases = [("nowhere", "'nowhere': not a motion of the library"), (24 + 1, "motion index 25"),
             (slower, "period 0.04"), (None, "the policy returned None")]
    for answer, words in cases:
        with pytest.raises(ValueError) as err:
            plate.control(sc, GOAL, library=LIBRARY, time=0.2, policy=lambda obs: answer)
        assert words in str(err.value) and "expected a library index" in str(err.value)

    def fails(obs):
        raise ZeroDivisionError("the policy's own error")

    with pytest.raises(ZeroDivisionError, match="the policy's own error"):
        plate.control(sc, GOAL, library=LIBRARY, time=0.2, policy=fails)
    env = plate.ControlEnv(sc, GOAL, library=LIBRARY, time=0.2)
    env.reset()
    with pytest.raises(ValueError, match="'nowhere': not a motion"):
        env.step("nowhere")


def test_control_parts_with_one_part_is_plate_controls_run_to_the_bit():
    # One part of weight 1: its camera stream is the camera's seed and its cost the single part's distance.
    one = plate.control_parts(scene(), {"parts": [{"goal": list(GOAL), "start": [-0.04, 0.03]}]}, library=LIBRARY,
                              truth=TRUTH, camera=CAMERA, time=3.0)
    run = plate.control(scene(), GOAL, library=LIBRARY, truth=TRUTH, camera=CAMERA, start=(-0.04, 0.03), time=3.0)
    assert len(one) == 1 and run.reached
    assert np.array_equal(one[0].truth, run.truth)
    assert np.array_equal(one[0].observed, run.observed, equal_nan=True)
    assert np.array_equal(one[0].motion, run.motion)
    assert one[0].summary["parts"][0]["time_to_goal_s"] == run.summary["time_to_goal_s"]


def test_control_parts_refuses_bad_parts_by_name():
    with pytest.raises(plate.InputError, match=r"<dict>: parts\[1\]\.weight"):
        plate.control_parts(scene(), {"parts": [{"goal": [0, 0]}, {"goal": [0, 0], "weight": -1}]}, library=LIBRARY,
                            time=1.0)
    with pytest.raises(ValueError, match="parts: expected a parts file's path or a dict"):
        plate.control_parts(scene(), [[0, 0]], library=LIBRARY, time=1.0)


@pytest.mark.skipif(not EXE, reason="PLATE_EXE (the program) not given")
def test_control_parts_gives_the_command_lines_run(tmp_path):
    parts = {"parts": [{"goal": [0.02, -0.01], "start": [0.0314, -0.0265]}, {"goal": [-0.02, 0.01], "start": [-0.027, -0.0175]}]}
    (tmp_path / "parts.json").write_text(json.dumps(parts))
    (tmp_path / "truth.json").write_text(json.dumps(TRUTH))
    (tmp_path / "camera.json").write_text(json.dumps(CAMERA))
    out = tmp_path / "run.csv"
    cli = subprocess.run([EXE, "control", SCENE, "--parts", str(tmp_path / "parts.json"), "--policy", "library",
                          "--library", LIBRARY, "--camera", str(tmp_path / "camera.json"), "--truth",
                          str(tmp_path / "truth.json"), "--time", "2", "--out", str(out)], capture_output=True, text=True)
    assert cli.returncode in (0, 1), cli.stderr
    expected = json.loads(cli.stdout)
    runs = plate.control_parts(scene(), parts, library=LIBRARY, truth=TRUTH, camera=CAMERA, time=2.0)
    wall = {"decision_mean_s", "decision_max_s", "decision_p99_s"}
    assert {k: v for k, v in runs[0].summary.items() if k not in wall} == {k: v for k, v in expected.items() if k not in wall}
    with open(out) as f:
        rows = list(csv.reader(f))[1:]
    cells = np.array([[float(c) if c else math.nan for c in r[:9]] for r in rows])
    for i, run in enumerate(runs):   # per part: obs_s_x_i, obs_s_y_i, x_i, y_i
        assert np.array_equal(cells[:, 1 + 4 * i:3 + 4 * i], run.observed[:, :2], equal_nan=True)
        assert np.array_equal(cells[:, 3 + 4 * i:5 + 4 * i], run.truth[:, :2])
