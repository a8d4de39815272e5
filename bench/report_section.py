"""Splices a study's section into the report's page (DIR/index.html) between its markers: replaced where
the markers are, else after the speed-accuracy section, else before </body>; written atomically. No page:
nothing to do (plate report includes DIR/data/<name>_section.html when it writes one)."""
import pathlib


def splice(out, begin, end, section):
    index = pathlib.Path(out) / "index.html"
    if not index.exists():
        return
    page = index.read_text()
    if begin in page and end in page:
        page = page[:page.index(begin) + len(begin)] + section + page[page.index(end):]
    elif "<!-- speed-accuracy:end -->" in page:   # (a page from before these markers: after the speed section)
        page = page.replace("<!-- speed-accuracy:end -->", "<!-- speed-accuracy:end -->" + begin + section + end, 1)
    else:
        page = page.replace("</body>", begin + section + end + "\n</body>", 1)
    tmp = index.with_suffix(".html.tmp")
    tmp.write_text(page)
    tmp.replace(index)
