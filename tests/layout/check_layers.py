#!/usr/bin/env python3
"""The layout shows the pipeline (issue 17, point 4): a file's folder tells its layer, and no file
includes a header of a layer above its own.

    symbolic  <  numeric  <  experiments, proofs, design (siblings: none includes another)
              <  reports, sweep  <  apps, python, bench  (tests may include anything)

Every #include, quoted or <angled>, is resolved to the file it names (beside the includer, then in
the layers' include folders; angled ones that resolve to no project file are system headers), and
the layer of the resolved file -- its top-level folder -- is compared with the includer's. C++
sources in a top-level folder that is no layer fail too (their layer would be unknown).
Exit 1 with the offending lines.
    check_layers.py SOURCE_DIR
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
RANK = {"symbolic": 0, "numeric": 1, "experiments": 2, "proofs": 2, "design": 2, "reports": 3, "sweep": 3, "apps": 4,
        "python": 4, "bench": 4}
NOT_LAYERS = {"tests", "examples", "scripts", "cmake", "scenes", "campaigns", ".ci", ".git"}   # no library code
INCLUDE_DIRS = ["symbolic", "numeric/include", "numeric/generated", "numeric/src", "experiments/include", "proofs",
                "design/include", "sweep/include", "reports", "reports/generated", "apps"]
include = re.compile(r'^\s*#\s*include\s+(["<])([^">]+)[">]', re.M)
SOURCES = (".cpp", ".hpp", ".h", ".cc", ".hh")


def layer_of(path):
    rel = path.relative_to(root)
    return rel.parts[0] if len(rel.parts) > 1 else None


problems, checked = [], 0
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
if problems:
    print("\n".join(problems))
    sys.exit(1)
print(f"layers: {checked} project includes checked, none reaches above its layer")
