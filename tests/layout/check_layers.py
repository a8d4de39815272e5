#!/usr/bin/env python3
"""The layout shows the pipeline (issue 17, point 4): a file's folder tells its layer, and no file
includes a header of a layer above its own.

    symbolic  <  numeric  <  experiments, proofs, design, identify, control (siblings: none includes another)
              <  reports, sweep  <  apps, python, bench, web  (tests may include anything)

Every #include, quoted or <angled>, is resolved to the file it names (beside the includer, then in
the layers' include folders; angled ones that resolve to no project file are system headers), and
the layer of the resolved file -- its top-level folder -- is compared with the includer's. C++
sources in a top-level folder that is no layer fail too (their layer would be unknown).
Within numeric/ the same holds between its internal levels (NUMERIC_LEVELS below, lowest first: what
needs nothing of plate < the model < dynamics and friction < the contact modes < the engine < simulate and
limit cycles < fields, fixed points and output < observations < robustness): no numeric file includes a numeric header of a higher
level, and every numeric source has a level (a new file gets a line in NUMERIC_LEVELS).
Exit 1 with the offending lines, also when no file at all was found to check (a wrong SOURCE_DIR).
    check_layers.py SOURCE_DIR
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
RANK = {"symbolic": 0, "numeric": 1, "experiments": 2, "proofs": 2, "design": 2, "identify": 2, "control": 2, "reports": 3, "sweep": 3, "apps": 4,
        "python": 4, "bench": 4,
        "web": 4}
NOT_LAYERS = {"tests", "examples", "scripts", "cmake", "scenes", "campaigns", ".ci", ".git"}   # no library code
INCLUDE_DIRS = ["symbolic", "numeric/include", "numeric/generated", "numeric/src", "experiments/include", "proofs",
                "design/include", "identify/include", "control/include", "sweep/include", "reports", "reports/generated", "apps"]
include = re.compile(r'^\s*#\s*include\s+(["<])([^">]+)[">]', re.M)
SOURCES = (".cpp", ".hpp", ".h", ".cc", ".hh", ".hxx")

# numeric's internal levels, lowest first, each with its files (relative to numeric/). A file may include
# headers of its own level or of a lower one, never of a higher one.
NUMERIC_LEVELS = [
    ("needs nothing of plate", ["include/plate/tasks.hpp", "src/tasks.cpp", "src/stepper.hpp", "src/events.hpp",
                                "src/lsan_suppressions.cpp",
                                "include/plate/progress.hpp", "src/progress.cpp"]),   # stop requests, progress
    ("model", ["include/plate/model.hpp", "src/model.cpp", "src/so3.hpp", "include/plate/scene_io.hpp",
               "src/scene_io.cpp", "src/input_reader.hpp", "include/plate/random_scene.hpp", "src/random_scene.cpp",
               "include/plate/friction.hpp", "include/plate/uncertainty.hpp", "src/uncertainty.cpp",
               "include/plate/measured_cycle.hpp", "src/measured_cycle.cpp",
               "include/plate/peaks.hpp", "src/peaks.cpp"]),   # friction's accessors are the part's (Part::friction)
    ("dynamics/friction", ["generated/plate_kernels.hpp", "include/plate/dynamics.hpp", "src/dynamics.cpp",
                           "src/friction.cpp",   # the gauge and the laws, over the generated kernels
                           "src/workspace.hpp"]),   # the kernels' scratch and the engine's private state
    ("modes", ["include/plate/modes.hpp", "src/modes.cpp",
               "src/models.hpp"]),            # the state layouts the engine integrates, with their modes
    ("engine", ["src/engine.hpp", "src/engine.cpp", "src/engine_step.hxx", "src/engine_events.hxx",
                "src/engine_modes.hxx", "src/engine_creep.hxx",
                "include/plate/simulate.hpp"]),   # the options, stops and samples the engine fills
    ("simulate/limit_cycle", ["src/simulate.cpp", "include/plate/limit_cycle.hpp", "src/limit_cycle.cpp",
                              "src/cycle_solvers.hpp", "src/shooting_cycle.cpp",
                              "src/newton_cycle.cpp", "src/newton_cycle_web.cpp"]),
    ("field/fixed_points", ["include/plate/field.hpp", "src/field.cpp", "src/fixed_points.cpp", "src/fixed_regions.hpp",
                            "src/fixed_regions.cpp", "src/rotating_attractors.cpp", "include/plate/output.hpp",
                            "src/output.cpp"]),
    ("observe", ["include/plate/observe.hpp", "src/observe.cpp",   # cameras filming simulations
                 "src/track_io.cpp"]),                             # and the track file
    ("robustness", ["include/plate/robustness.hpp", "src/robustness.cpp", "src/robustness_sensitivity.cpp",
                    "src/robustness_json.cpp"]),
]
NUMERIC_LEVEL = {name: (rank, level) for rank, (level, names) in enumerate(NUMERIC_LEVELS) for name in names}


def layer_of(path):
    rel = path.relative_to(root)
    return rel.parts[0] if len(rel.parts) > 1 else None


def numeric_level(path):
    """(rank, level name) of a file under numeric/, None if it has no level."""
    return NUMERIC_LEVEL.get(path.relative_to(root / "numeric").as_posix())


problems, checked, files, numeric_files, numeric_checked = [], 0, 0, 0, 0
for f in sorted(root.rglob("*")):
    if f.suffix not in SOURCES or not f.is_file():
        continue
    top = layer_of(f)
    if top is None or top.startswith("build") or top in NOT_LAYERS:
        continue
    if top not in RANK:
        problems.append(f"{f.relative_to(root)}: C++ source in '{top}/', which is no layer (see check_layers.py)")
        continue
    rank = RANK[top]
    files += 1
    own_level = None
    if top == "numeric":
        numeric_files += 1
        own_level = numeric_level(f)
        if own_level is None:
            problems.append(f"{f.relative_to(root)}: a numeric source with no level (add it to NUMERIC_LEVELS in "
                            f"tests/layout/check_layers.py)")
    for kind, name in include.findall(f.read_text(errors="replace")):
        candidates = ([f.parent / name] if kind == '"' else []) + [root / d / name for d in INCLUDE_DIRS]
        target = next((c.resolve() for c in candidates if c.is_file()), None)
        if target is None:
            if kind == '"':
                problems.append(f"{f.relative_to(root)}: #include \"{name}\" resolves to no file of the project")
            continue   # a system header
        checked += 1
        try:
            owner = layer_of(target)
        except ValueError:
            problems.append(f"{f.relative_to(root)}: #include \"{name}\" leaves the project ({target})")
            continue
        if owner not in RANK:
            problems.append(f"{f.relative_to(root)}: includes {target.relative_to(root)}, outside every layer")
        elif RANK[owner] > rank or (RANK[owner] == rank and owner != top):
            problems.append(f"{f.relative_to(root)} ({top}) includes \"{name}\" from {owner}, "
                            f"{'a layer above' if RANK[owner] > rank else 'a sibling layer'}")
        elif owner == "numeric" and top == "numeric" and own_level is not None:
            numeric_checked += 1
            target_level = numeric_level(target)
            if target_level is not None and target_level[0] > own_level[0]:
                problems.append(f"{f.relative_to(root)} (numeric level '{own_level[1]}') includes \"{name}\" of the "
                                f"higher level '{target_level[1]}'")
if files == 0 or checked == 0 or numeric_files == 0 or numeric_checked == 0:
    problems.append(f"no files to check under {root}: {files} sources, {checked} project includes, "
                    f"{numeric_files} numeric sources, {numeric_checked} includes within numeric (a wrong SOURCE_DIR?)")
if problems:
    print("\n".join(problems))
    sys.exit(1)
print(f"layers: {files} sources, {checked} project includes checked, none reaches above its layer; numeric: "
      f"{numeric_files} sources in {len(NUMERIC_LEVELS)} levels, {numeric_checked} includes within numeric checked, "
      f"none reaches a higher level")
