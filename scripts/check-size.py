#!/usr/bin/env python3
"""Sizes (issue 57): no hand-written function over 150 lines, no hand-written source file over 800.

    scripts/check-size.py [ROOT]                 exit 1 listing each offender (file:line, name, length),
                                                 exit 0 with a one-line summary when there is none
    scripts/check-size.py --report [N] [ROOT]    every function over N lines (default 150) and every
                                                 file over the file limit, longest first; exit 0
    scripts/check-size.py --self-test            the scanner on small sources with known answers
    (--function-lines, --file-lines change the limits; ROOT defaults to the project this script is in)

Checked: C++ (.cpp .hpp .h .cc .hh) and Python (.py) files under ROOT. Skipped: generated code (the
folders numeric/generated/ and reports/generated/, and any file whose first lines carry a "generated"
or "do not edit" banner), build folders (build*, any folder holding a CMakeCache.txt), hidden folders
(.git, .ci) and third-party folders (third_party, 3rdparty, external, extern, vendor, _deps).

A C++ function's extent is found by a brace-matching scanner that first blanks comments, string and
character literals (raw strings too; 20'000 digit separators are no character literals) and
preprocessor lines, so braces there do not count. A '{' opens a function body when the text before it
(since the last ';', '{' or '}' of the enclosing scope) ends in a parameter list -- ')' and optionally
const, noexcept, override, a trailing return type, or a constructor's member initialisers -- or in a
lambda introducer; namespace, extern "C", class, struct, union and enum bodies are scopes, not
functions (member functions defined in a class are functions), and any other brace at namespace or
class scope is an initialiser. Everything up to the matching '}' belongs to the function, lambdas and
local classes included. Its length counts lines from the line of its name (the signature) to that of
the closing brace, both included. Python functions and methods are measured from `def` to their last
line (ast); functions nested in a function count as part of it.
"""
import argparse
import ast
import pathlib
import re
import sys

SOURCES_CPP = {".cpp", ".hpp", ".h", ".cc", ".hh"}
SOURCES_PY = {".py"}
GENERATED_DIRS = {("numeric", "generated"), ("reports", "generated")}
THIRD_PARTY = {"third_party", "third-party", "3rdparty", "external", "extern", "vendor", "_deps", "node_modules"}
# A banner: a comment line among the first ten that starts with "generated"/"@generated", or says "do not edit".
BANNER = re.compile(r"^\s*(?://|/\*|\*|#|%|<!--)\s*(?:@?generated\b|.*\bdo not edit\b)", re.I | re.M)


# --- which files ---------------------------------------------------------------------------------------

def is_generated(path, text):
    rel = path.parts
    if any(rel[i:i + 2] == d for d in GENERATED_DIRS for i in range(len(rel) - 1)):
        return True
    return BANNER.search("\n".join(text.splitlines()[:10])) is not None


def source_files(root):
    """Hand-written C++ and Python sources under root, sorted; generated ones skipped."""
    out = []

    def walk(d):
        for p in sorted(d.iterdir()):
            if p.is_dir():
                if (p.name.startswith(".") or p.name.startswith("build") or p.name in THIRD_PARTY
                        or (p / "CMakeCache.txt").exists()):
                    continue
                walk(p)
            elif p.is_file() and p.suffix in SOURCES_CPP | SOURCES_PY:
                out.append(p)

    walk(root)
    return out


# --- C++: blanking -------------------------------------------------------------------------------------

IDENT = re.compile(r"[A-Za-z_]\w*")
RAW_PREFIXES = {"R", "u8R", "uR", "UR", "LR"}


def blank(text):
    """text with comments, literals' contents and preprocessor lines replaced by spaces (newlines and
    offsets kept; a string keeps its quotes, so extern "C" reads extern "")."""
    out = list(text)
    n, i = len(text), 0
    line_start = True   # only whitespace so far on this line (outside comments)

    def wipe(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    def skip_block_comment(k):   # k at '/*'; returns the index after '*/'
        e = text.find("*/", k + 2)
        e = n if e < 0 else e + 2
        wipe(k, e)
        return e

    def skip_line_comment(k):    # k at '//'; up to the newline (a trailing backslash continues it)
        e = k
        while True:
            e = text.find("\n", e)
            if e < 0:
                e = n
                break
            if text[e - 1] == "\\":
                e += 1
                continue
            break
        wipe(k, e)
        return e

    while i < n:
        c = text[i]
        if c == "\n":
            line_start = True
            i += 1
            continue
        if c in " \t\r\f\v":
            i += 1
            continue
        if line_start and c == "#":   # a preprocessor directive, with its continuation lines
            k = i
            while k < n and text[k] != "\n":
                if text.startswith("/*", k):
                    k = skip_block_comment(k)
                    continue
                if text.startswith("//", k):
                    k = skip_line_comment(k)
                    break
                if text[k] == "\\" and k + 1 < n and text[k + 1] == "\n":
                    k += 2
                    continue
                k += 1
            wipe(i, k)
            i = k
            continue
        line_start = False
        if text.startswith("//", i):
            i = skip_line_comment(i)
        elif text.startswith("/*", i):
            i = skip_block_comment(i)
        elif c.isalpha() or c == "_":
            m = IDENT.match(text, i)
            e = m.end()
            if m.group() in RAW_PREFIXES and e < n and text[e] == '"':   # R"delim( ... )delim"
                p = text.find("(", e + 1)
                delim = text[e + 1:p]
                close = text.find(")" + delim + '"', p + 1)
                close = n if close < 0 else close + len(delim) + 2
                wipe(e + 1, close - 1)
                i = close
            else:
                i = e
        elif c.isdigit() or (c == "." and i + 1 < n and text[i + 1].isdigit()):
            k = i + 1   # a pp-number: digits, letters, '.', digit separators, exponent signs
            while k < n:
                d = text[k]
                if d.isalnum() or d in "._":
                    k += 1
                elif d == "'" and k + 1 < n and (text[k + 1].isalnum() or text[k + 1] == "_"):
                    k += 2
                elif d in "+-" and text[k - 1] in "eEpP":
                    k += 1
                else:
                    break
            i = k
        elif c in "\"'":
            k = i + 1
            while k < n and text[k] != c and text[k] != "\n":
                k += 2 if text[k] == "\\" else 1
            wipe(i + 1, min(k, n))
            i = k + 1
        else:
            i += 1
    return "".join(out)


# --- C++: what a '{' opens -----------------------------------------------------------------------------

QUALIFIERS = r"(?:\s*(?:const|volatile|noexcept(?:\s*\([^()]*\))?|override|final|mutable|constexpr|&&|&|try))*"
ENDS_IN_PARAMETERS = re.compile(r"\)" + QUALIFIERS + r"\s*$")
ACCESS = re.compile(r"^\s*(?:(?:public|private|protected)\s*:(?!:)\s*)+")
TYPE_KEYWORD = re.compile(r"\b(?:class|struct|union|enum)\b")
NAME_BEFORE = re.compile(r"((?:[A-Za-z_]\w*\s*(?:<[^<>;{}]*>)?\s*::\s*)*(?:operator\s*(?:\(\s*\)|\[\s*\]|[^\s\w(]+|[\w:\s<>*&]+?)|~?[A-Za-z_]\w*))\s*(?:<[^<>;{}]*>)?\s*$")


def paren_depths(s):
    """depth[k]: nesting of () and [] at s[k] (the bracket itself counted outside)."""
    depth, d = [], 0
    for ch in s:
        if ch in ")]":
            d -= 1
        depth.append(d)
        if ch in "([":
            d += 1
    return depth


def strip_templates(s):
    """s without its leading template<...> headers."""
    while True:
        m = re.match(r"\s*template\s*<", s)
        if not m:
            return s
        d, k = 1, m.end()
        while k < len(s) and d:
            d += {"<": 1, ">": -1}.get(s[k], 0)
            k += 1
        s = s[k:]


def matching_open(s, close):
    """Index of the bracket that s[close] (')' or ']') closes, or -1."""
    pair = {")": "(", "]": "["}[s[close]]
    d = 0
    for k in range(close, -1, -1):
        if s[k] == s[close]:
            d += 1
        elif s[k] == pair:
            d -= 1
            if d == 0:
                return k
    return -1


def ctor_colon(h):
    """Offset of a constructor's ':' (after its parameter list, at depth 0), or -1."""
    depth = paren_depths(h)
    for m in re.finditer(r"\)" + QUALIFIERS + r"\s*:(?!:)", h):
        if depth[m.start()] == 0 and (m.start() == 0 or h[m.start() - 1] != ":"):
            return m.end() - 1
    return -1


def lambda_intro_end(h):
    """h ends in a lambda introducer [..] (no parameter list): its '[' offset, else -1."""
    t = h.rstrip()
    if not t.endswith("]"):
        return -1
    k = matching_open(t, len(t) - 1)
    before = t[:k].rstrip() if k >= 0 else ""
    if k < 0 or (before and before[-1] not in "=(,{" and not before.endswith("return")):
        return -1
    return k


def classify(head):
    """What a '{' after `head` (blanked text since the scope's last ';', '{' or '}') opens:
    ('namespace', name), ('type', name), ('function', offset of the parameter list's '(' or of a
    lambda's '[' in head) or ('init', None)."""
    h = ACCESS.sub("", head)
    off = len(head) - len(h)
    core = strip_templates(h)
    off += len(h) - len(core)
    s = core.strip()
    if re.match(r"(?:inline\s+)?namespace\b", s):
        m = re.match(r"(?:inline\s+)?namespace\s+([\w:]+)", s)
        return "namespace", (m.group(1) if m else "")
    if re.fullmatch(r'extern\s*""', s):
        return "namespace", ""
    first_paren = s.find("(")
    kw = TYPE_KEYWORD.search(s if first_paren < 0 else s[:first_paren])
    if kw:
        m = re.match(r"\s*(?:\w+\s*(?:\([^()]*\))?\s+)*?(?:class|struct|union|enum)(?:\s+(?:class|struct))?\s+(?:alignas\s*\([^()]*\)\s*)?([A-Za-z_]\w*)", s)
        return "type", (m.group(1) if m else "")
    colon = ctor_colon(core)
    if colon >= 0:   # Foo::Foo(...) : a_(x), b_{y} {  -- the body comes after initialisers ending in ) or }
        tail = core.rstrip()
        if tail.endswith(")") or tail.endswith("}"):
            k = matching_open(core, core.rfind(")", 0, colon + 1))
            return "function", off + k
        return "init", None
    stripped = core.rstrip()
    arrow = None
    depth = paren_depths(stripped)
    for m in re.finditer(r"->", stripped):
        if depth[m.start()] == 0:
            arrow = m.start()
            break
    if arrow is not None:   # a trailing return type: -> T {
        before = stripped[:arrow].rstrip()
        if ENDS_IN_PARAMETERS.search(before):
            close = before.rfind(")")
            return "function", off + matching_open(stripped, close)
    if ENDS_IN_PARAMETERS.search(stripped):
        close = stripped.rfind(")")
        return "function", off + matching_open(stripped, close)
    k = lambda_intro_end(stripped)
    if k >= 0:
        return "function", off + k
    return "init", None


def function_name(orig, head_start, par):
    """The name before the parameter list (or lambda introducer) at orig[par], and its offset."""
    before = orig[head_start:par]
    if orig[par] == "(" and before.rstrip().endswith("]"):   # a lambda with parameters
        t = before.rstrip()
        par = head_start + matching_open(t, len(t) - 1)
        before = orig[head_start:par]
    if orig[par] == "[":   # a lambda: named by the variable it initialises, if any
        m = re.search(r"([A-Za-z_]\w*)\s*(?:\[[^\]]*\])?\s*=\s*$", before)
        if m:
            return m.group(1), head_start + m.start(1)
        return "<lambda>", par
    m = NAME_BEFORE.search(before)
    if not m:
        return "<unnamed>", par
    name = re.sub(r"\s+", "", m.group(1)) if "operator" not in m.group(1) else " ".join(m.group(1).split())
    if re.fullmatch(r"[A-Z][A-Z0-9_]*", name):   # a macro's body (TEST_CASE, PYBIND11_MODULE): its arguments too
        close = matching_open_forward(orig, par)
        args = " ".join(orig[par:close + 1].split())
        name += args if len(args) <= 70 else args[:67] + "...)"
    return name, head_start + m.start(1)


def matching_open_forward(s, k):
    d = 0
    for j in range(k, len(s)):
        if s[j] == "(":
            d += 1
        elif s[j] == ")":
            d -= 1
            if d == 0:
                return j
    return len(s) - 1


def cpp_functions(text):
    """[(name, first line, last line)] of the functions defined in C++ source text."""
    b = blank(text)
    line_of = _line_index(text)
    found = []
    # each scope: [kind, head_start, name]; function scopes are walked through at once
    stack = [["namespace", 0, ""]]
    i, n = 0, len(b)
    while i < n:
        c = b[i]
        top = stack[-1]
        if c == ";":
            top[1] = i + 1
        elif c == "," and top[0] == "init":
            top[1] = i + 1   # an initialiser's elements: a lambda in a table is a function of its own
        elif c == "{":
            kind, arg = classify(b[top[1]:i])
            if kind == "function":
                name, at = function_name(text, top[1], top[1] + arg)
                scopes = [s[2] for s in stack if s[0] == "type" and s[2]]
                d, k = 1, i + 1
                while k < n and d:
                    d += {"{": 1, "}": -1}.get(b[k], 0)
                    k += 1
                found.append(("::".join(scopes + [name]), line_of(at), line_of(k - 1)))
                top[1] = k
                i = k
                continue
            stack.append([kind, i + 1, arg or ""])
        elif c == "}":
            if len(stack) > 1:
                closed = stack.pop()
                if closed[0] != "init":
                    stack[-1][1] = i + 1
        i += 1
    return found


def _line_index(text):
    starts = [0] + [m.end() for m in re.finditer("\n", text)]

    def line_of(offset):
        lo, hi = 0, len(starts) - 1
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if starts[mid] <= offset:
                lo = mid
            else:
                hi = mid - 1
        return lo + 1

    return line_of


# --- Python --------------------------------------------------------------------------------------------

def py_functions(text, source="<text>"):
    """[(name, def line, last line)] of the functions and methods (not those nested in a function)."""
    found = []

    def visit(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                found.append((prefix + child.name, child.lineno, child.end_lineno))
            elif isinstance(child, ast.ClassDef):
                visit(child, prefix + child.name + ".")
            elif not isinstance(child, ast.Lambda):
                visit(child, prefix)   # if/try/with at module or class level

    visit(ast.parse(text, filename=source), "")
    return found


# --- the check -----------------------------------------------------------------------------------------

def measure(root):
    """(files [(rel, lines)], functions [(rel, line, name, length)], skipped generated count)."""
    files, functions, generated = [], [], 0
    for path in source_files(root):
        rel = path.relative_to(root)
        text = path.read_text(errors="replace")
        if is_generated(rel, text):
            generated += 1
            continue
        files.append((rel, text.count("\n") + (0 if text.endswith("\n") or not text else 1)))
        found = py_functions(text, str(rel)) if path.suffix in SOURCES_PY else cpp_functions(text)
        functions += [(rel, first, name, last - first + 1) for name, first, last in found]
    return files, functions, generated


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("root", nargs="?", default=str(pathlib.Path(__file__).resolve().parent.parent))
    ap.add_argument("--report", nargs="?", type=int, const=-1, default=None, metavar="N",
                    help="list every function over N lines (default: the function limit) and exit 0")
    ap.add_argument("--function-lines", type=int, default=150)
    ap.add_argument("--file-lines", type=int, default=800)
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        return self_test()
    root = pathlib.Path(a.root).resolve()
    if not root.is_dir():
        print(f"check-size: {root}: no such folder", file=sys.stderr)
        return 2
    files, functions, generated = measure(root)
    if not files:
        print(f"check-size: no C++ or Python sources under {root}", file=sys.stderr)
        return 2
    limit = a.function_lines if a.report is None or a.report < 0 else a.report
    long_functions = sorted((f for f in functions if f[3] > limit), key=lambda f: (-f[3], str(f[0]), f[1]))
    long_files = sorted((f for f in files if f[1] > a.file_lines), key=lambda f: (-f[1], str(f[0])))
    for rel, line, name, length in long_functions:
        print(f"{rel}:{line}: function {name}: {length} lines (over {limit})")
    for rel, length in long_files:
        print(f"{rel}: file: {length} lines (over {a.file_lines})")
    counts = (f"{len(files)} files, {len(functions)} functions checked ({generated} generated files skipped)")
    if a.report is not None:
        print(f"check-size: {len(long_functions)} functions over {limit} lines, {len(long_files)} files over "
              f"{a.file_lines}; {counts}")
        return 0
    if long_functions or long_files:
        print(f"check-size: FAILED: {len(long_functions)} functions over {limit} lines, {len(long_files)} files "
              f"over {a.file_lines}; {counts}")
        return 1
    print(f"check-size: no function over {limit} lines, no file over {a.file_lines}; {counts}")
    return 0


# --- self-test -----------------------------------------------------------------------------------------

SELF_TEST_CPP = r'''// A comment with a brace { that is no code
#include <x.hpp>
#define OPEN {
namespace plate {
namespace {
const char* s = "}{ \" }";
const char c = '{', d = '}';
const long sep[] = {1'000, 20'000'000L};
auto raw = R"x(} { )" )x";
struct Box : Base<int> {
    int v{3};
    Box(int a, int b) : v{a}, w_(b) {
        v += 1;
    }
    int get() const noexcept { return v; /* { */ }
    auto twice() -> int {
        return 2 * v;
    }
  private:
    int w_;
};
enum class E { A, B };
const int table[] = {1, 2, 3};
template <class T>
T f(T x) {
    auto g = [&](int y) {
        if (y) { return x + 1'000; }
        return x + sizeof("{") + sizeof('{');
    };
#define CLOSE } /* } */
    return g(1);
}
}  // namespace
extern "C" {
int c_api(void) { return 0; }
}
static const auto handler = [](int k) {
    return k;
};
TEST_CASE("a claim", "[tag]") {
    SECTION("x") { }
}
const auto noargs = [] {
    return 1;
};
}  // namespace plate
'''
SELF_TEST_EXPECT = [("Box::Box", 12, 14), ("Box::get", 15, 15), ("Box::twice", 16, 18), ("f", 25, 32),
                    ("c_api", 35, 35), ("handler", 37, 39), ('TEST_CASE("a claim", "[tag]")', 40, 42),
                    ("noargs", 43, 45)]
SELF_TEST_PY = '''import os
class A:
    def m(self):
        def inner():
            pass
        return 1
if os:
    def g():
        return [
            1]
'''


def self_test():
    ok = True
    got = cpp_functions(SELF_TEST_CPP)
    if got != SELF_TEST_EXPECT:
        print(f"self-test C++: expected {SELF_TEST_EXPECT}\n               got      {got}")
        ok = False
    got = py_functions(SELF_TEST_PY)
    if got != [("A.m", 3, 6), ("g", 8, 10)]:
        print(f"self-test Python: got {got}")
        ok = False
    if not is_generated(pathlib.Path("x/y.hpp"), "// GENERATED by derive.\n") or \
            is_generated(pathlib.Path("x/y.hpp"), "// The generated kernels against the reference\n") or \
            not is_generated(pathlib.Path("numeric/generated/k.hpp"), ""):
        print("self-test: generated-file detection wrong")
        ok = False
    print("check-size self-test: " + ("passed" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
