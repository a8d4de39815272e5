#!/usr/bin/env python3
"""The mutation catalogue (tests/mutations/catalogue.json, issue 56): each entry is a one-line change a
physicist would call a real bug; the tests it names must notice it. For each mutation this script writes
the change into a scratch copy of the tree (never into the checkout), rebuilds what it touches, runs the
named tests and records which of them failed. A mutation none of its tests fails on SURVIVES: the tests
cannot tell that model from the right one.

    scripts/mutants.py [--only ID,...] [--subset N --pick-by TEXT] [--no-baseline] [--work DIR]
                       [--out RESULTS.json] [--report DIR]
    scripts/mutants.py --check [--build BUILD]

--check       the catalogue only (no build): every entry well formed, its line found exactly once in its
              file (after its anchor), and, with --build, every test it names known to that build.
--subset N    N mutations chosen by --pick-by (CI: the commit hash), a different few on every commit.
--budget S    start no further mutation once S seconds have passed (at least one runs; the others are
              listed as not run).
--no-baseline skip running the named tests on the unmutated scratch build first (CI: the suite just
              passed on the same sources).
--report DIR  also write DIR/data/mutations.json and the report's section DIR/data/mutations_section.html,
              spliced into DIR/index.html when the report is there.

Exit codes: 0 every mutation killed; 1 a mutation survived, a named test failed without any mutation, or a
mutation did not build; 2 a bad catalogue or bad arguments (the entry and field named); 130 interrupted.
The results (JSON, with each mutation's killers and seconds) are written only when the run is complete.
"""
import argparse
import concurrent.futures
import datetime
import hashlib
import json
import os
import pathlib
import platform
import re
import shutil
import signal
import subprocess
import sys
import threading
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
FIELDS = {"id", "file", "anchor", "find", "replace", "meaning", "tests", "regenerate"}
REQUIRED = ("id", "file", "find", "replace", "meaning", "tests")
# A test name for the derivation's own cross-checks: an entry with "regenerate" may name it, and is then
# killed where derive refuses to generate kernels from the mutated derivation.
DERIVE = "derive"


class BadInput(Exception):
    pass


def load_catalogue(path):
    """The entries, each checked against the tree; BadInput names the entry and the field."""
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise BadInput(f"{path}: not readable as JSON: {e}")
    if not isinstance(data, dict) or not isinstance(data.get("mutations"), list) or not data["mutations"]:
        raise BadInput(f"{path}: expected an object with a non-empty list 'mutations'")
    seen = set()
    for k, m in enumerate(data["mutations"]):
        where = f"{path}: mutations[{k}]" + (f" ({m.get('id')})" if isinstance(m, dict) and "id" in m else "")
        if not isinstance(m, dict):
            raise BadInput(f"{where}: expected an object")
        for f in REQUIRED:
            if f not in m:
                raise BadInput(f"{where}: field '{f}' missing")
        for f in m:
            if f not in FIELDS:
                raise BadInput(f"{where}: unknown field '{f}' (expected one of {', '.join(sorted(FIELDS))})")
        for f in ("id", "file", "find", "replace", "meaning") + (("anchor",) if "anchor" in m else ()):
            if not isinstance(m[f], str) or not m[f]:
                raise BadInput(f"{where}: field '{f}' must be a non-empty string")
        if not re.fullmatch(r"[a-z0-9][a-z0-9-]*", m["id"]):
            raise BadInput(f"{where}: field 'id' must be lower-case words joined by '-'")
        if m["id"] in seen:
            raise BadInput(f"{where}: field 'id' repeats an earlier entry's")
        seen.add(m["id"])
        if "\n" in m["find"] or "\n" in m["replace"]:
            raise BadInput(f"{where}: fields 'find' and 'replace' must be within one line")
        if m["find"] == m["replace"]:
            raise BadInput(f"{where}: field 'replace' equals 'find': not a mutation")
        if not isinstance(m["tests"], list) or not m["tests"] or not all(isinstance(t, str) and t for t in m["tests"]):
            raise BadInput(f"{where}: field 'tests' must be a non-empty list of test names")
        if not isinstance(m.get("regenerate", False), bool):
            raise BadInput(f"{where}: field 'regenerate' must be true or false")
        src = ROOT / m["file"]
        if not src.is_file():
            raise BadInput(f"{where}: field 'file': no file {m['file']} in the tree")
        mutated_text(m, src.read_text(), where)
    return data["mutations"]


def mutated_text(m, text, where):
    """TEXT with the entry's line changed: 'find' must occur exactly once (in the block that starts at
    'anchor', up to the first line that is a lone '}', if an anchor is given)."""
    start, end = 0, len(text)
    if "anchor" in m:
        if text.count(m["anchor"]) != 1:
            raise BadInput(f"{where}: field 'anchor': found {text.count(m['anchor'])} times in {m['file']}, expected once")
        start = text.index(m["anchor"])
        end = text.find("\n}\n", start)   # the anchor's function or block: to its closing brace
        end = len(text) if end < 0 else end
    n = text.count(m["find"], start, end)
    if n != 1:
        raise BadInput(f"{where}: field 'find': found {n} times in {m['file']}" +
                       (" in the anchor's block" if "anchor" in m else "") + ", expected once (the code moved? update the entry)")
    i = text.index(m["find"], start, end)
    return text[:i] + m["replace"] + text[i + len(m["find"]):]


def catch_spec(name):
    """A Catch2 test spec naming one case (or a [tag]) exactly: its special characters escaped."""
    return name if name.startswith("[") else re.sub(r"([\\,\[\]*~])", r"\\\1", name)


def ctest_regex(name):
    """An anchored ctest regex for one test name: every character but letters, digits, blanks and '_'
    as '.' (ctest's regular expressions differ between versions in what a backslash escapes)."""
    return "^" + re.sub(r"[^A-Za-z0-9 _]", ".", name) + "$"


def known_tests(build):
    """(Catch2 cases of plate_tests, ctest names) of a build."""
    exe = build / "tests" / "plate_tests"
    cases = subprocess.run([str(exe), "--list-test-names-only"], capture_output=True, text=True).stdout
    names = subprocess.run(["ctest", "--test-dir", str(build), "-N"], capture_output=True, text=True).stdout
    ctest = {m.group(1) for m in re.finditer(r"Test +#\d+: (.*)", names)}
    return {c.strip() for c in cases.splitlines() if c.strip()}, ctest


def check_tests_known(mutations, build):
    cases, ctest = known_tests(build)
    if not cases:
        raise BadInput(f"{build}/tests/plate_tests lists no test cases (not built?)")
    for m in mutations:
        for t in m["tests"]:
            if t == DERIVE:
                ok = m.get("regenerate", False)
            elif t.startswith("ctest:"):
                ok = t[6:] in ctest
            elif t.startswith("["):
                # Every alternative of the spec must list a case: Catch2's --warn NoTests fails a run where
                # one matches nothing, which would count as a kill.
                ok = all(subprocess.run([str(build / "tests" / "plate_tests"), term, "--list-test-names-only"],
                                        capture_output=True, text=True).stdout.strip()
                         for term in re.split(r"(?<!\\),", t))
            else:
                ok = t in cases
            if not ok:
                raise BadInput(f"mutation {m['id']}: field 'tests': no test '{t}' in {build}")


def tracked_files():
    out = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], capture_output=True, check=True).stdout
    return [p for p in out.decode().split("\0") if p]


def sync(src_dir):
    """Makes the scratch copy's tracked files equal to the checkout's (its own edits and those of an
    earlier mutation undone); a changed file gets a new time stamp, so that make rebuilds from it."""
    changed = 0
    for rel in tracked_files():
        a, b = ROOT / rel, src_dir / rel
        if not a.is_file():
            continue
        data = a.read_bytes()
        if b.is_file() and b.read_bytes() == data:
            continue
        b.parent.mkdir(parents=True, exist_ok=True)
        b.write_bytes(data)
        shutil.copymode(a, b)
        changed += 1
    return changed


LOG_LOCK = threading.Lock()


def run(cmd, log, cwd=None, env=None, timeout=None):
    """CMD's exit code (None: timed out); its output appended to LOG in one piece (tests run side by side)."""
    t0 = time.monotonic()
    try:
        r = subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
        rc, out = r.returncode, r.stdout
    except subprocess.TimeoutExpired as e:
        rc, out = None, (e.stdout or b"") + f"(timed out after {timeout} s)\n".encode()
    with LOG_LOCK, open(log, "ab") as f:
        f.write(("$ " + " ".join(cmd) + "\n").encode() + out + f"(exit {rc}, {time.monotonic() - t0:.1f} s)\n".encode())
    return rc


class Scratch:
    """A copy of the tree in WORK/src, built in WORK/src/build: the same layout as the checkout and its
    build/, so that ccache (with base_dir at the checkout) finds what the checkout's build compiled."""

    def __init__(self, work, log):
        self.src = work / "src"
        self.build = self.src / "build"
        self.log = log
        self.env = dict(os.environ)
        self.env.setdefault("CCACHE_BASEDIR", str(ROOT.parent))

    def prepare(self):
        self.src.mkdir(parents=True, exist_ok=True)
        sync(self.src)
        cmd = ["cmake", "-S", str(self.src), "-B", str(self.build), "-DCMAKE_BUILD_TYPE=Release"]
        if shutil.which("ccache"):
            cmd.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        if run(cmd, self.log, env=self.env) != 0:
            raise RuntimeError(f"configuring the scratch build failed (see {self.log})")

    def regenerate(self):
        """The kernels and the derivation's report regenerated from the (mutated) symbolic derivation;
        False where derive refuses (one of its cross-checks failed)."""
        return run(["cmake", "--build", str(self.build), "-j", str(os.cpu_count() or 2), "--target", "kernels"], self.log,
                   env=self.env) == 0

    def make(self):
        jobs = str(os.cpu_count() or 2)
        return run(["cmake", "--build", str(self.build), "-j", jobs, "--target", "plate_tests", "plate"], self.log,
                   env=self.env) == 0


def run_test(scratch, name, timeout, log):
    """(failed, seconds): one named test on the scratch build; a timeout counts as failed."""
    t0 = time.monotonic()
    if name.startswith("ctest:"):
        cmd = ["ctest", "--test-dir", str(scratch.build), "-R", ctest_regex(name[6:]), "--no-tests=error"]
    else:
        cmd = [str(scratch.build / "tests" / "plate_tests"), catch_spec(name), "--warn", "NoTests"]
    rc = run(cmd, log, cwd=scratch.src, env=scratch.env, timeout=timeout)
    return rc != 0, time.monotonic() - t0


def run_tests(scratch, names, timeout, log):
    jobs = max(1, min(2, os.cpu_count() or 1))
    with concurrent.futures.ThreadPoolExecutor(jobs) as pool:
        futures = {n: pool.submit(run_test, scratch, n, timeout, log) for n in names}
        return {n: f.result() for n, f in futures.items()}


def pick(mutations, n, key):
    """N mutations chosen by KEY (a commit hash): a different few on every commit, the same on a rerun."""
    order = sorted(mutations, key=lambda m: hashlib.sha256((key + m["id"]).encode()).hexdigest())
    chosen = {m["id"] for m in order[:n]}
    return [m for m in mutations if m["id"] in chosen]


def one_mutation(scratch, m, timeout, log):
    t0 = time.monotonic()
    path = scratch.src / m["file"]
    path.write_text(mutated_text(m, path.read_text(), f"mutation {m['id']}"))
    regenerated = scratch.regenerate() if m.get("regenerate", False) else True
    built = regenerated and scratch.make()
    build_s = time.monotonic() - t0
    result = {"id": m["id"], "file": m["file"], "find": m["find"], "replace": m["replace"], "meaning": m["meaning"],
              "tests": m["tests"], "build_seconds": round(build_s, 1)}
    if not regenerated and DERIVE in m["tests"]:
        # The derivation's own cross-checks (symbolic/) refused to generate kernels from the wrong model.
        result.update(outcome="killed", killed=True, killed_by=[DERIVE], test_seconds=0)
    elif not built:
        result.update(outcome="did not build", killed=False, killed_by=[], test_seconds=0)
    else:
        names = [n for n in m["tests"] if n != DERIVE]
        outcome = run_tests(scratch, names, timeout, log)
        killers = [n for n in names if outcome[n][0]]
        result.update(outcome="killed" if killers else "SURVIVED", killed=bool(killers), killed_by=killers,
                      test_seconds=round(sum(s for _, s in outcome.values()), 1))
    sync(scratch.src)
    return result


def machine():
    cpu = platform.processor() or platform.machine()
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} hardware threads"


def write_atomic(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--catalogue", default=str(ROOT / "tests" / "mutations" / "catalogue.json"))
    ap.add_argument("--check", action="store_true", help="check the catalogue against the tree (no build)")
    ap.add_argument("--build", help="with --check: a build whose tests the catalogue must name")
    ap.add_argument("--only", help="comma-separated mutation ids")
    ap.add_argument("--subset", type=int, help="run N mutations chosen by --pick-by")
    ap.add_argument("--pick-by", default="", help="the text that chooses the subset (CI: the commit hash)")
    ap.add_argument("--no-baseline", action="store_true", help="skip the unmutated run of the named tests")
    ap.add_argument("--work", default=str(ROOT / "build-mutants"), help="scratch folder (default build-mutants/)")
    ap.add_argument("--out", help="results JSON (written when the run is complete)")
    ap.add_argument("--report", help="a report folder: write its mutation section there")
    ap.add_argument("--timeout", type=float, default=600, help="seconds per test before it counts as failed")
    ap.add_argument("--budget", type=float, help="start no further mutation after this many seconds (CI); at least one runs")
    a = ap.parse_args()
    try:
        mutations = load_catalogue(pathlib.Path(a.catalogue))
        if a.only:
            ids = a.only.split(",")
            unknown = [i for i in ids if i not in {m["id"] for m in mutations}]
            if unknown:
                raise BadInput(f"--only: no mutation '{unknown[0]}' in {a.catalogue}")
            mutations = [m for m in mutations if m["id"] in ids]
        if a.subset is not None:
            if a.subset < 1 or not a.pick_by:
                raise BadInput("--subset: expected a count >= 1 and --pick-by TEXT")
            mutations = pick(mutations, a.subset, a.pick_by)
        if a.check:
            if a.build:
                check_tests_known(mutations, pathlib.Path(a.build).resolve())
            print(f"mutants: {len(mutations)} mutations apply to this tree" +
                  (f" and name tests of {a.build}" if a.build else ""))
            return 0
    except BadInput as e:
        print(f"mutants: {e}", file=sys.stderr)
        return 2
    work = pathlib.Path(a.work).resolve()
    work.mkdir(parents=True, exist_ok=True)
    log = work / "mutants.log"
    log.write_text("")
    scratch = Scratch(work, log)
    t_start = time.monotonic()
    print(f"mutants: {len(mutations)} mutations; scratch copy {scratch.src}; log {log}", flush=True)
    scratch.prepare()
    if not scratch.make():
        print(f"mutants: the unmutated scratch copy does not build (see {log})", file=sys.stderr)
        return 1
    try:
        check_tests_known(mutations, scratch.build)
    except BadInput as e:
        print(f"mutants: {e}", file=sys.stderr)
        return 2
    if not a.no_baseline:
        names = sorted({t for m in mutations for t in m["tests"] if t != DERIVE})
        base = run_tests(scratch, names, a.timeout, log)
        bad = [n for n in names if base[n][0]]
        if bad:
            print(f"mutants: without any mutation these tests fail, so they cannot judge one: {bad} (see {log})",
                  file=sys.stderr)
            return 1
        print(f"mutants: baseline: the {len(names)} named tests pass unmutated", flush=True)
    results, left = [], []
    for m in mutations:
        if a.budget is not None and results and time.monotonic() - t_start > a.budget:
            left.append(m["id"])
            continue
        r = one_mutation(scratch, m, a.timeout, log)
        results.append(r)
        who = ", ".join(r["killed_by"]) if r["killed_by"] else "none of " + str(len(m["tests"])) + " tests"
        print(f"mutants: {r['outcome']:13} {m['id']}: {who} ({r['build_seconds']} s build, {r['test_seconds']} s tests)",
              flush=True)
    killed = sum(r["killed"] for r in results)
    if left:
        print(f"mutants: the budget of {a.budget:g} s was spent; not run: {', '.join(left)}", flush=True)
    summary = {"score": f"{killed} of {len(results)} killed", "killed": killed, "mutations": len(results),
               "not_run": left,
               "commit": subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True,
                                        text=True).stdout.strip(),
               "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
               "machine": machine(), "seconds": round(time.monotonic() - t_start, 1),
               "subset": a.subset is not None or bool(a.only), "results": results}
    text = json.dumps(summary, indent=1) + "\n"
    if a.out:
        write_atomic(pathlib.Path(a.out), text)
    if a.report:
        sys.path.insert(0, str(ROOT / "tests" / "mutations"))
        from section import write_section  # noqa: E402
        write_section(pathlib.Path(a.report), summary)
    print(f"mutants: {summary['score']} in {summary['seconds']} s", flush=True)
    return 0 if killed == len(results) else 1


def interrupted(*_):
    # sync() in one_mutation's path does not run on a signal: the next run's sync undoes the edit; the
    # checkout itself is never written.
    print("mutants: interrupted; no results written", file=sys.stderr)
    os._exit(130)


if __name__ == "__main__":
    signal.signal(signal.SIGINT, interrupted)
    signal.signal(signal.SIGTERM, interrupted)
    sys.exit(main())
