#!/usr/bin/env python3
"""Doxygen's INPUT_FILTER for the public headers: their plain `//` comments as Doxygen comments.

The headers are written to be read top to bottom (STYLE.md), with plain comments; this turns them into
documentation on the fly, line for line (Doxygen's line numbers stay right), the files unchanged:
  - the block at the top of a file, before `#pragma once`, documents a group named after the file
    (field.hpp: field_hpp) that holds every declaration of the file, so that a page can show one
    header (breathe's doxygenfile would repeat the namespace on every page);
  - a block of `//` lines directly above a declaration (no blank line between) documents it;
  - a trailing `// ...` after a declaration documents that member (`///<`), and so do the `//` lines
    below it that start in the same column (its continuation).
Only at namespace and class scope: comments inside function bodies stay comments, and so do blocks
followed by a blank line, a preprocessor line or a closing brace, and `// --- headings ---`. The
comment text is escaped for Doxygen (backslash, @, <, >, &, #, %, $, dashes), `code spans` become
<tt>, and lines indented past the text (tables, formulas, samples) are kept verbatim. Two changes to
the code, for Sphinx's C++ parser and breathe: digit separators dropped (20'000'000), and a class
member defined at namespace scope hidden (it is shown where its class declares it).

  doxygen_filter.py HEADER        prints the filtered header
  doxygen_filter.py --self-test   checks the rules above on a small header (exit 1 naming a broken one)
"""
import os
import re
import sys

SPECIAL = re.compile(r"([\\@<>&#%$\"])")
DASHES = re.compile(r"-{2,3}")
NUMBERED = re.compile(r"\b([A-Z][A-Za-z]+)(?= [0-9])")
HEADING = re.compile(r"^//\s*---")
DIGIT_SEPARATOR = re.compile(r"(?<=[0-9])'(?=[0-9])")
OUT_OF_CLASS = re.compile(r"^\s*(inline\s+)?[\w:<>,\s*&]+?\s[*&]?[A-Z]\w*::~?\w+\s*\(")
SCOPE_OPENER = re.compile(r"^(template\s*<[^{]*>\s*)?(inline\s+)?(namespace|struct|class|union|enum)\b")


def escape(text):
    """Doxygen's special characters escaped; `code spans` as <tt> (Markdown is off: Doxyfile)."""
    parts = text.split("`")
    if len(parts) % 2 == 0:   # (an unpaired backtick: no code span)
        parts = [text]
    parts = [plain(p) if i % 2 == 0 else "<tt>" + plain(p, link_names=False) + "</tt>" for i, p in enumerate(parts)]
    return "".join(parts)


def plain(text, link_names=True):
    """Prose escaped: special characters; dashes kept as typed (Doxygen makes -- an en dash, which
    breathe shows as an entity); no link from a numbered name of the paper ("Observation 1": a word
    before a number is not the struct of that name)."""
    text = SPECIAL.sub(r"\\\1", text)
    text = DASHES.sub(lambda m: "\\" + m.group(0), text)
    return NUMBERED.sub(r"%\1", text) if link_names else text


def split_code_comment(line):
    """(code, column of a trailing `//` or -1), strings and character literals skipped."""
    i, n, quote = 0, len(line), None
    while i < n:
        ch = line[i]
        if quote:
            if ch == "\\":
                i += 2
                continue
            if ch == quote:
                quote = None
        elif ch in "\"'":
            # (a digit separator, 20'000'000, is not a character literal)
            if ch == "'" and i > 0 and line[i - 1].isalnum() and i + 1 < n and line[i + 1].isalnum():
                i += 1
                continue
            quote = ch
        elif line.startswith("//", i):
            return line[:i], i
        elif line.startswith("/*", i):
            end = line.find("*/", i + 2)
            if end < 0:
                return line[:i], -1
            i = end + 2
            continue
        i += 1
    return line, -1


def documentable(code):
    """Whether a code line (its comment removed) starts a declaration a comment above may document."""
    s = code.strip()
    if not s or s.startswith("#") or s.startswith("}") or s.startswith("{"):
        return False
    if re.match(r"^(namespace\b|using\s+namespace\b|public:|private:|protected:|extern\s+\"C\")", s):
        return False
    if re.match(r"^(class|struct)\s+\w+\s*;", s):   # (a forward declaration: documented where it is defined)
        return False
    return True


class Scopes:
    """Brace nesting: whether the current line is at namespace or class scope (not in a body)."""

    def __init__(self):
        self.stack = []
        self.kinds = []   # (namespace, struct, class, union, enum or body, beside stack)
        self.pending = ""   # the statement so far (since the last ; { or })

    def at_scope(self):
        return all(kind == "scope" for kind in self.stack)

    def in_class(self):
        return bool(self.stack) and self.kinds[-1] != "namespace"

    def feed(self, code):
        if code.lstrip().startswith("#"):   # (a preprocessor line ends a statement)
            self.pending = ""
            return
        code = re.sub(r'"(\\.|[^"\\])*"', '""', code)
        for ch in code:
            if ch == "{":
                head = self.pending.strip()
                opener = SCOPE_OPENER.match(head)
                after = head[opener.end():] if opener else ""
                self.stack.append("scope" if opener and "(" not in after else "body")
                self.kinds.append(opener.group(3) if opener else "body")
                self.pending = ""
            elif ch == "}":
                if self.stack:
                    self.stack.pop()
                    self.kinds.pop()
                self.pending = ""
            elif ch == ";":
                self.pending = ""
            elif ch != "\n":
                self.pending += ch
        self.pending += " "


def filter_header(path, lines):
    out = list(lines)
    scopes = Scopes()
    pragma = next((i for i, l in enumerate(lines) if l.strip().startswith("#pragma once")), None)
    # The file's own block (the comment lines before #pragma once) documents a group named after the
    # file, which holds every declaration of the file: the pages show a header by its group
    # (doxygengroup), one header at a time. #pragma once carries the group's definition, the first
    # namespace line its start, the last closing brace (the namespace's) its end.
    if pragma is not None:
        head = [i for i in range(pragma) if lines[i].lstrip().startswith("//")]
        name = os.path.basename(path)
        group = name.replace(".", "_")
        doc_block(lines, head, out, (pragma, "\\defgroup %s %s" % (group, name)))
        first = next((i for i, l in enumerate(lines) if re.match(r"^namespace [\w:]+ \{\s*$", l)), None)
        last = max((i for i, l in enumerate(lines) if l.startswith("}")), default=None)
        if first is not None and last is not None:
            out[first] = lines[first].rstrip("\n") + " /** \\addtogroup %s */ /** @{ */\n" % group
            out[last] = "/** @} */ " + lines[last]
    hidden_from = None     # the brace depth at which a hidden definition ends (None: none open)
    block = []             # indices of the comment-only lines just above this one
    trailing_col = -1      # the column of the previous line's trailing member comment (-1: none)
    start = pragma + 1 if pragma is not None else 0
    for i in range(start, len(lines)):
        line = lines[i]
        stripped = line.strip()
        if HEADING.match(stripped):   # (a section heading documents nothing, nor does the block above it)
            block, trailing_col = [], -1
            continue
        if stripped.startswith("//"):
            col = line.index("//")
            if trailing_col >= 0 and col == trailing_col and scopes.at_scope():
                out[i] = to_doc(line, "///<")
                continue
            trailing_col = -1
            block.append(i)
            continue
        if not stripped:
            block, trailing_col = [], -1
            continue
        code, col = split_code_comment(line)
        at_scope = scopes.at_scope()
        # (digit separators, 20'000'000: Sphinx's C++ parser does not read them in a default value)
        if DIGIT_SEPARATOR.search(code):
            code = DIGIT_SEPARATOR.sub("", code)
            out[i] = code + line[len(split_code_comment(line)[0]):]
        # A class member defined at namespace scope (Part::friction in friction.hpp) is documented where
        # the class declares it; here it is hidden, else the page would show it twice.
        hide = hidden_from is None and at_scope and not scopes.in_class() and OUT_OF_CLASS.match(code)
        if hide:
            hidden_from = len(scopes.stack)
            out[i] = "/** \\cond */ " + out[i]
        if at_scope and documentable(code):
            doc_block(lines, block, out)
        block, trailing_col = [], -1
        if col >= 0 and at_scope and documentable(code) and not code.rstrip().endswith("{"):
            out[i] = ("/** \\cond */ " if hide else "") + code + to_doc(line[col:], "///<")
            trailing_col = col
        scopes.feed(code)
        if hidden_from is not None and len(scopes.stack) == hidden_from and re.search(r"[;}]\s*$", code):
            out[i] = out[i].rstrip("\n") + " /** \\endcond */\n"
            hidden_from = None
    return out


def doc_block(lines, block, out, last=None):
    """The comment lines `block` as one documentation block, and the line `last` = (index, text) after
    them if given (a Doxygen command). A run of lines indented past the text (a table, a formula, a
    JSON sample) -- unless they continue a list item -- is kept as laid out, verbatim: such a block is
    written as one /** ... */ comment (in a /// block Doxygen 1.9.4 leaves the slashes, or an asterisk,
    in a verbatim's lines), each line where it was."""
    texts = [lines[j][lines[j].index("//") + 2:].rstrip("\n") for j in block]
    runs = verbatim_runs(texts)
    if not runs or any("*/" in t for t in texts):
        for j in block:
            out[j] = to_doc(lines[j], "///")
        if last:
            out[last[0]] = "/// " + last[1] + "\n"
        return
    verbatim = {k for a, b in runs for k in range(a, b + 1)}
    starts, ends = {a for a, _ in runs}, {b for _, b in runs}
    for k, j in enumerate(block):
        pre = lines[j][:lines[j].index("//")]
        text = texts[k] if k in verbatim else escape(texts[k])
        if k in starts and k == 0:
            text = "\\verbatim" + text
        if k + 1 in starts:
            text += " \\verbatim"
        if k in ends:
            text += " \\endverbatim"
        out[j] = pre + ("/**" if k == 0 else "  ") + text + ("\n" if last or k + 1 < len(block) else " */\n")
    if last:
        out[last[0]] = "   " + last[1] + " */\n"


def verbatim_runs(texts):
    """[(first, last)] of the runs of lines indented past the text, list items' continuations aside."""
    runs, in_list, k = [], False, 0
    while k < len(texts):
        t = texts[k]
        if re.match(r"^\s*- ", t):
            in_list = True
        elif not t.startswith("  "):
            in_list = False
        if t.startswith("   ") and not in_list:
            end = k
            while end + 1 < len(texts) and texts[end + 1].startswith("   "):
                end += 1
            runs.append((k, end))
            k = end + 1
            continue
        k += 1
    return runs


def to_doc(comment_line, marker):
    """A `// text` line as `MARKER text`, its indentation kept and its text escaped."""
    k = comment_line.index("//")
    text = comment_line[k + 2:].rstrip("\n")
    return comment_line[:k] + marker + escape(text) + "\n"


SAMPLE = """\
// The sample header.
#pragma once

#include <string>

namespace plate {

// --- a heading ------------------------------------------------------
// Documents S: a < b & c # d, `x<y>`, e.g. -- a dash.
struct S {
    int n = 20'000'000;   // the count
                          // (continued)
    int f() const {
        // inside a body
        return n;   // trailing, in a body
    }
};
// Followed by a blank line: a comment.

// A table:
//   a    b
//        c
void g();
inline int S::f2() const { return 1; }
class T;   // t.hpp
}   // namespace plate
"""

# (line of SAMPLE, what the filtered line must contain, what the rule is)
EXPECTED = [
    (0, "/// The sample header.", "the file's block documents the file's group"),
    (1, "\\defgroup sample_hpp sample.hpp", "#pragma once carries the group's definition"),
    (5, "/** \\addtogroup sample_hpp */ /** @{ */", "the namespace line opens the group"),
    (7, "// --- a heading", "a heading stays a comment"),
    (8, "/// Documents S: a \\< b \\& c \\# d, <tt>x\\<y\\></tt>, e.g. \\-- a dash.", "a block above a declaration, escaped"),
    (10, "int n = 20000000;   ///< the count", "a trailing comment, digit separators dropped"),
    (11, "///< (continued)", "a trailing comment's continuation in its column"),
    (13, "// inside a body", "a comment in a function body stays"),
    (14, "return n;   // trailing, in a body", "a trailing comment in a function body stays"),
    (17, "// Followed by a blank line", "a block before a blank line stays"),
    (19, "/** A table: \\verbatim", "a table is verbatim in a /** */ block"),
    (21, "       c \\endverbatim", "the table's last line ends the verbatim"),
    (22, "void g();", "the declaration the block documents"),
    (23, "/** \\cond */ inline int S::f2() const { return 1; } /** \\endcond */", "an out-of-class member hidden"),
    (24, "class T;   // t.hpp", "a forward declaration's comment stays"),
    (25, "/** @} */ }", "the namespace's closing brace closes the group"),
]


def self_test():
    lines = SAMPLE.splitlines(keepends=True)
    out = filter_header("sample.hpp", lines)
    failed = [(k, want, rule, out[k]) for k, want, rule in EXPECTED if want not in out[k]]
    if len(out) != len(lines) or "".join(out).count("\n") != len(lines):
        failed.append((-1, "%d lines" % len(lines), "line for line", "%d lines" % len(out)))
    for k, want, rule, got in failed:
        print("doxygen_filter.py: %s: line %d is %r, not containing %r" % (rule, k + 1, got.rstrip("\n"), want))
    if failed:
        sys.exit(1)
    print("doxygen_filter.py: %d rules hold on the sample" % (len(EXPECTED) + 1))


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    with open(sys.argv[1], encoding="utf-8") as f:
        lines = f.readlines()
    sys.stdout.write("".join(filter_header(sys.argv[1], lines)))


if __name__ == "__main__":
    main()
