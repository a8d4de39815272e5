#!/usr/bin/env python3
"""The layout shows the pipeline (issue 17, point 4): a file's folder tells its layer, and no file
includes a header of a layer above its own.

    symbolic  <  numeric  <  experiments, proofs, design (siblings: none includes another)
              <  reports  <  apps, python, bench  (tests may include anything)

Every quoted #include is resolved to the file it names (by the include folders of the layers) and
its layer compared with the includer's. Exit 1 with the offending lines.
    check_layers.py SOURCE_DIR
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
RANK = {"symbolic": 0, "numeric": 1, "experiments": 2, "proofs": 2, "design": 2, "reports": 3, "apps": 4, "python": 4, "bench": 4}
# Where each layer's headers are found by their include names.
INCLUDE_DIRS = {"symbolic": ["symbolic"], "numeric": ["numeric/include", "numeric/generated", "numeric/src"],
                "experiments": ["experiments/include"], "proofs": ["proofs"], "design": ["design/include"], "reports": ["reports", "reports/generated"],
                "apps": ["apps"], "python": [], "bench": []}
include = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)

problems, checked = [], 0
for layer, rank in RANK.items():
    for f in sorted((root / layer).rglob("*")):
        if f.suffix not in (".cpp", ".hpp", ".h") or not f.is_file():
            continue
        for name in include.findall(f.read_text(errors="replace")):
            checked += 1
            owners = [l for l, dirs in INCLUDE_DIRS.items() for d in dirs if (root / d / name).is_file()]
            if (f.parent / name).is_file():          # beside the includer: its own layer
                owners = [layer]
            if not owners:
                problems.append(f"{f.relative_to(root)}: #include \"{name}\" resolves to no layer's header")
                continue
            owner = min(owners, key=lambda l: RANK[l])
            if RANK[owner] > rank or (RANK[owner] == rank and owner != layer):
                problems.append(f"{f.relative_to(root)} ({layer}) includes \"{name}\" from {owner}, "
                                f"{'a layer above' if RANK[owner] > rank else 'a sibling layer'}")
if problems:
    print("\n".join(problems))
    sys.exit(1)
print(f"layers: {checked} includes checked, none reaches above its layer")
