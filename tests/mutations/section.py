"""The report's section for a run of the mutation catalogue (scripts/mutants.py --report DIR): the
mutation score, and per mutation its meaning, the line changed, the tests that killed it (or SURVIVED)
and the seconds it took. Written to DIR/data/mutations_section.html and DIR/data/mutations.json, and
spliced into DIR/index.html between the mutations markers when the page is there."""
import html
import json
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent.parent / "bench"))
from report_section import splice  # noqa: E402

BEGIN, END = "<!-- mutations:begin -->", "<!-- mutations:end -->"


def section(summary):
    e = html.escape
    rows = []
    for r in summary["results"]:
        verdict = ('<span class="pass">killed</span>' if r["killed"] else f'<span class="fail">{e(r["outcome"])}</span>')
        by = "<br>".join(e(t) for t in r["killed_by"]) or "none of: " + "<br>".join(e(t) for t in r["tests"])
        rows.append(f"<tr><td><code>{e(r['id'])}</code></td><td>{e(r['meaning'])}<br><small><code>{e(r['file'])}</code>: "
                    f"<code>{e(r['find'])}</code> &rarr; <code>{e(r['replace'])}</code></small></td><td>{verdict}</td>"
                    f"<td><small>{by}</small></td><td>{r['build_seconds']} + {r['test_seconds']}</td></tr>")
    scope = ("a subset of the catalogue" if summary["subset"] else "the whole catalogue")
    return f"""<h2>Mutation score</h2>
<p>Each mutation is a one-line change a physicist would call a real bug (tests/mutations/catalogue.json); the tests
named beside it must fail on it. This run ({scope}, commit <code>{e(summary['commit'][:12])}</code>, {e(summary['date'])},
{e(summary['machine'])}, {summary['seconds']} s): <b>{e(summary['score'])}</b>. Run it again with
<code>scripts/mutants.py --report DIR</code>.</p>
<table><tr><th>mutation</th><th>what it breaks, and the line changed</th><th>verdict</th><th>killed by</th>
<th>seconds (build + tests)</th></tr>
{chr(10).join(rows)}
</table>
"""


def write_section(out, summary):
    out = pathlib.Path(out)
    data = out / "data"
    data.mkdir(parents=True, exist_ok=True)
    text = section(summary)
    for name, content in (("mutations.json", json.dumps(summary, indent=1) + "\n"), ("mutations_section.html", text)):
        tmp = data / (name + ".tmp")
        tmp.write_text(content)
        tmp.replace(data / name)
    splice(out, BEGIN, END, text)
