"""plate: sliding manipulation on a vibrating 6-DoF plate (Vose, Umbanhowar & Lynch).

Where does a part resting on a periodically shaken plate go?  The same library as the ``plate``
program, from Python::

    import plate
    scene = plate.load_scene("scenes/fig4.json")          # or plate.scene_from_dict({...})
    c = plate.twist(scene, at=(0.03, -0.02, 1.0))          # asymptotic twist (36) of the limit cycle
    f = plate.field(scene, grid=9)                         # numpy arrays f.x, f.y, f.theta, f.twist
    fp = plate.fixed_points(f)                             # fp.points: stable, unstable, saddle
    tr = plate.simulate(scene, start=(0.03, -0.02, 1.0), time=5.0, dynamics="full")
    d = plate.design(plate.load_scene("scenes/fig1_point.json"), sink=(0.02, -0.01))   # d.scene, d.verified
    r = plate.robustness(d.scene, "scenes/uncertainty/ppod.json", draws=50)          # r.outcomes, r.radius95
    cam = {"stroboscopic": {"phase": 0.25}, "noise": {"xy_mm": 0.1}, "frame": "world"}
    tk = plate.observe(scene, cam, start=(0.03, -0.02, 1.0), time=5.0)   # tk.t, tk.q: what a camera records
    est = plate.identify(scene, [tk], ["mu_k1", "mu_k2", "mu_k3"])     # est.estimates, est.intervals
    plate.write_track_csv(tk, "track.csv"); tk = plate.read_track_csv("track.csv")
    lib = "scenes/control/fig1_point/library.json"
    run = plate.control(plate.load_scene("scenes/fig1_point.json"), (0.02, -0.01), library=lib, time=5.0,
                        start=(-0.04, 0.03), camera=cam)          # run.t, run.truth, run.motion, run.summary
    run = plate.control(..., policy=lambda obs: "e_fast")      # a Python policy: obs -> a motion, once a period
    runs = plate.control_parts(scene, {"parts": [{"goal": [0.02, -0.01]}, {"goal": [-0.02, 0.01]}]},
                               library="scenes/control/fig1_point/multi.json", time=30.0)   # one run per part
    env = plate.ControlEnv(plate.load_scene("scenes/fig1_point.json"), (0.02, -0.01), library=lib, time=5.0)
    obs = env.reset(seed=0); obs, reward, terminated, truncated, info = env.step("still")   # one plate period

Results carry numpy arrays and ``summary``, the command line's JSON as a dict.  Errors raise
``plate.InputError`` (a ValueError; bad scenes, with the file and field named as the command line
names them), ValueError (bad options) or RuntimeError.  The GIL is released while the library works.
"""
import json as _json
from typing import Any, Dict

from ._plate import (Camera, ControlEnv, ControlRun, Cycle, Design, Field, FixedLine, FixedPoint, FixedPoints, Identification, InputError,
                     Progress, Robustness, RotatingAttractor, Scene, Stop, StuckRegion, Track, Trajectory, axis_peaks, bench, check_track_scene, coning_rate, control, control_parts, corner_peaks, design, field,
                     fixed_points, frame_stamps, identify, load_camera, load_scene, observe, observe_at,
                     orientation_harmonics, parse_camera, parse_scene, proofs, random_scene, report, read_track_csv, robustness, scene_id,
                     simulate, sweep, twist, uncertain_parameters, write_track_csv)
from ._plate import __version__ as _compiled_version

__version__ = _compiled_version
__all__ = ["Camera", "ControlEnv", "ControlRun", "Cycle", "Design", "Field", "FixedLine", "FixedPoint", "FixedPoints", "Identification", "InputError",
           "Progress", "Robustness", "RotatingAttractor", "Scene", "Stop", "StuckRegion", "Track", "Trajectory", "axis_peaks", "bench", "check_track_scene", "coning_rate", "control", "control_parts", "corner_peaks", "design",
           "field", "fixed_points", "frame_stamps", "identify", "load_camera", "load_scene", "observe", "observe_at", "orientation_harmonics",
           "parse_camera", "parse_scene", "proofs", "random_scene", "read_track_csv", "report", "robustness", "scene_from_dict", "scene_id",
           "scene_to_dict", "simulate", "sweep", "twist", "uncertain_parameters", "write_track_csv"]


def scene_from_dict(d: Dict[str, Any], source: str = "<dict>") -> Scene:
    """A scene from a dict in the scene file's form (see scenes/*.json); checked as a file is."""
    return parse_scene(_json.dumps(d), source)


def scene_to_dict(scene: Scene) -> Dict[str, Any]:
    """The scene in the file form, as a dict (scene_from_dict(scene_to_dict(s)) gives s back)."""
    d: Dict[str, Any] = _json.loads(scene.to_json())
    return d


Scene.to_dict = scene_to_dict  # type: ignore  # (methods added in Python: the stubs declare them)
Scene.from_dict = staticmethod(scene_from_dict)  # type: ignore
