#!/usr/bin/env python3
"""The mutation catalogue still applies to this tree and names tests this build has (scripts/mutants.py
--check); and the check can fail: doctored copies of the catalogue (a line the code no longer has, a
line found twice, a test that does not exist, a tag alternative that lists no case, a field missing, an entry that changes nothing) are each
refused with exit 2 and the entry and field named.

    check_catalogue.py SOURCE_DIR BUILD_DIR
"""
import json
import pathlib
import subprocess
import sys
import tempfile

src, build = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
script = src / "scripts" / "mutants.py"
catalogue = json.loads((src / "tests" / "mutations" / "catalogue.json").read_text())
failures = []


def check(args, want_rc, want_text=""):
    r = subprocess.run([sys.executable, str(script), "--check", "--build", str(build)] + args, capture_output=True, text=True)
    ok = r.returncode == want_rc and want_text in r.stdout + r.stderr
    print(("ok   " if ok else "FAIL ") + f"{' '.join(args) or 'the catalogue'}: exit {r.returncode} "
          f"(expected {want_rc}){': ' + (r.stdout + r.stderr).strip() if r.returncode else ''}")
    if not ok:
        failures.append(args)


check([], 0, f"{len(catalogue['mutations'])} mutations apply")
with tempfile.TemporaryDirectory() as tmp:
    def doctored(name, change, expect):
        d = json.loads(json.dumps(catalogue))
        change(d["mutations"][0])
        path = pathlib.Path(tmp) / (name + ".json")
        path.write_text(json.dumps(d))
        check(["--catalogue", str(path)], 2, expect)
    first = catalogue["mutations"][0]["id"]
    doctored("gone", lambda m: m.update(find=m["find"] + " /* not in the code */"), f"({first}): field 'find': found 0 times")
    doctored("twice", lambda m: (m.pop("anchor", None), m.update(file="tests/mutations/catalogue.json", find='"id"')),
             f"({first}): field 'find': found")
    doctored("no-test", lambda m: m["tests"].append("a test nobody wrote"), f"mutation {first}: field 'tests': no test")
    doctored("tag-alternative-empty", lambda m: m["tests"].append("[field],[no such tag]"),
             f"mutation {first}: field 'tests': no test '[field],[no such tag]'")
    doctored("no-meaning", lambda m: m.pop("meaning"), f"({first}): field 'meaning' missing")
    doctored("no-change", lambda m: m.update(replace=m["find"]), f"({first}): field 'replace' equals 'find'")
sys.exit(1 if failures else 0)
