// Internal: what the report's pages share -- number formatting, escaping, the figure context
// (gnuplot SVGs beside the page, data files under data/), the style sheet.
#pragma once

#include "plate/output.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <cerrno>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace plate::report::html {
namespace fs = std::filesystem;

inline std::string fmt(double x, int p = 4) {
    std::ostringstream s;
    s << std::setprecision(p) << x;
    return s.str();
}

inline std::string esc(const std::string& s) {
    std::string o;
    for (char c : s) {
        if (c == '<')
            o += "&lt;";
        else if (c == '>')
            o += "&gt;";
        else if (c == '&')
            o += "&amp;";
        else if (c == '"')
            o += "&quot;";
        else if (c == '\'')
            o += "&#39;";
        else
            o += c;
    }
    return o;
}


// gnuplot SCRIPT run in folder `dir`, stderr to `log`, without a shell (a folder's name is data, not
// a command: through a shell, a quote in --out would run what follows it).
inline bool run_gnuplot(const fs::path& dir, const std::string& script, const fs::path& log) {
    const pid_t pid = ::fork();
    if (pid < 0) return false;
    if (pid == 0) {
        const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);   // (before chdir: log may be relative)
        if (fd >= 0) ::dup2(fd, 2);
        if (::chdir(dir.c_str()) != 0) ::_exit(127);
        ::execlp("gnuplot", "gnuplot", script.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return false;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

struct Ctx {
    fs::path dir;
    std::ostringstream html;
    std::vector<std::pair<std::string, double>> timings;
    int figures = 0;

    template <class F>
    void timed(const std::string& what, F&& f) {
        const auto t0 = std::chrono::steady_clock::now();
        plate::progress_line("report: %s...\n", what.c_str());
        f();
        timings.push_back({what, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()});
    }
    // The page's contents (anchor, heading) and the checks it states, for the list and the verdict
    // table at the top: a check belongs to the section whose heading came last.
    struct Check {
        std::string section, what, id, shown;   // shown: the verdict's words where the page states it
        bool ok;
        bool paper = false;   // the paper's print compared with the derivation: "differs" is a finding, not a failure
    };
    std::vector<std::pair<std::string, std::string>> contents;
    std::vector<Check> checks;
    // A section's heading with its anchor, listed in the contents.
    std::string heading(const std::string& title, const std::string& id) {
        contents.push_back({id, title});
        return "<h2 id=\"" + id + "\">" + esc(title) + "</h2>\n";
    }
    // A check's verdict where the page states it: `pass_text` or `fail_text` marked pass or fail, with
    // the anchor the verdict table links to.
    std::string verdict(const std::string& what, bool ok, const std::string& pass_text = "pass",
                        const std::string& fail_text = "FAIL") {
        const std::string id = "check-" + std::to_string(checks.size() + 1);
        checks.push_back({contents.empty() ? std::string() : contents.back().second, what, id, ok ? pass_text : fail_text, ok});
        return "<span id=\"" + id + "\" class=\"" + (ok ? "pass" : "fail") + "\">" + esc(ok ? pass_text : fail_text) + "</span>";
    }
    // An equation as printed in the paper against the derivation's: "agrees" or "differs" (the row says why).
    std::string paper_check(const std::string& equation, bool agrees) {
        const std::string v = verdict("equation " + equation + " as printed in the paper", agrees, "agrees", "differs");
        checks.back().paper = true;
        return v;
    }
    std::ofstream data(const std::string& name) {
        std::ofstream o(dir / "data" / name);
        o << std::setprecision(9);
        return o;
    }
    // Runs a gnuplot script (cwd = dir) that must write `name`.svg; adds the <img>. The SVG has a
    // fixed size (shown at it, or the page's width if narrower; a click enlarges it to the window).
    void plot(const std::string& name, const std::string& script, const std::string& caption,
              const std::string& size = "640,480") {
        const fs::path gp = dir / "data" / (name + ".gp");
        std::ofstream(gp) << "set terminal svg size " << size << " fixed background rgb 'white' font 'sans,11'\n"
                          << "set output '" << name << ".svg'\n"
                          << script;
        if (!run_gnuplot(dir, "data/" + name + ".gp", dir / "data" / (name + ".log")) || !fs::exists(dir / (name + ".svg")))
            throw std::runtime_error("gnuplot failed on " + gp.string() + " (see data/" + name + ".log)");
        html << "<figure><img src=\"" << name << ".svg\" alt=\"" << esc(caption) << "\"><figcaption>" << caption
             << "</figcaption></figure>\n";
        ++figures;
    }
};

inline const char* kStyle = R"(<style>
body{font-family:sans-serif;max-width:1700px;margin:2em auto;padding:0 1em;color:#222}
p,ul,ol,table,.math{max-width:1100px}
h1,h2,h3{color:#123}table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #bbb;padding:3px 8px;font-size:90%}
th{background:#eef}.pass{color:#080;font-weight:bold}.fail{color:#b00;font-weight:bold}figure{display:inline-block;margin:.5em}
figure{max-width:calc(100% - 1em)}figure img{max-width:100%;height:auto;border:1px solid #ddd;cursor:zoom-in}
figcaption{font-size:85%;max-width:640px}code,pre{background:#f6f6f6}
#zoom{display:none;position:fixed;top:0;left:0;right:0;bottom:0;background:rgba(0,0,0,.75);z-index:9;cursor:zoom-out}
#zoom img{display:block;margin:2vh auto;width:auto;height:96vh;max-width:96vw;object-fit:contain;background:#fff}
pre{overflow-x:auto;padding:.5em}.math{overflow-x:auto}</style>
)";


// The report's page keeps the speed-accuracy section (written by `plate bench`) between these.
inline const char* kSpeedBegin = "<!-- speed-accuracy:begin -->";
inline const char* kSpeedEnd = "<!-- speed-accuracy:end -->";
// ... and the campaigns' scaling study (bench/scaling.py) between these.
inline const char* kCampaignsBegin = "<!-- campaigns:begin -->";
inline const char* kCampaignsEnd = "<!-- campaigns:end -->";
inline const char* kPeersBegin = "<!-- peers:begin -->";
inline const char* kPeersEnd = "<!-- peers:end -->";
// ... and the mutation catalogue's score (scripts/mutants.py --report) between these.
inline const char* kMutationsBegin = "<!-- mutations:begin -->";
inline const char* kMutationsEnd = "<!-- mutations:end -->";

// First in <head>: records every error the page meets (script errors, resources that fail to load,
// console.error, rejected promises) for the browser check.
inline const char* kErrorTrap =
    "<script>window.__errors=[];window.addEventListener('error',function(e){var t=e.target;"
    "window.__errors.push(t&&t!==window&&(t.src||t.href)?'failed to load '+(t.src||t.href):String(e.message));},true);"
    "window.addEventListener('unhandledrejection',function(e){window.__errors.push('unhandled rejection: '+e.reason);});"
    "(function(){var ce=console.error;console.error=function(){window.__errors.push([].join.call(arguments,' '));"
    "ce.apply(console,arguments);};})();</script>\n";

// Last in <body>: click a figure to see it as large as the window (click again to close); and, for
// scripts/check-report.sh, a second after loading (errors thrown by late scripts count) the body
// states what a person would see: data-images (every
// image decoded: ok:N, else missing:SRC,...), data-errors (none, else the errors), data-math (every
// $$...$$ typeset by KaTeX: ok:N, else why not), data-figure-width (the narrowest figure as shown, px).
inline const char* kPageCheck =
    "<div id=\"zoom\"><img alt=\"enlarged figure\"></div>\n<script>(function(){var z=document.getElementById('zoom');"
    "document.addEventListener('click',function(e){var t=e.target;if(t.closest&&t.closest('figure')&&t.tagName==='IMG'){"
    "z.firstChild.src=t.src;z.style.display='block';}else if(t===z||t.parentNode===z){z.style.display='none';}});})();\n"
    "window.addEventListener('load',function(){setTimeout(function(){var b=document.body;var "
    "imgs=[].slice.call(document.querySelectorAll('figure img'));"
    "var bad=imgs.filter(function(i){return !(i.complete&&i.naturalWidth>0);});"
    "b.setAttribute('data-images',bad.length?'missing:'+bad.map(function(i){return "
    "i.getAttribute('src');}).join(','):'ok:'+imgs.length);"
    "var w=imgs.map(function(i){return i.getBoundingClientRect().width;});"
    "b.setAttribute('data-figure-width',w.length?Math.round(Math.min.apply(null,w)):0);"
    "var k=document.querySelectorAll('.katex').length,ke=document.querySelectorAll('.katex-error').length;"
    "var left=b.innerText.indexOf('$$')>=0;"
    "b.setAttribute('data-math',ke?'errors:'+ke:left?(window.katex?'untypeset $$ left':'KaTeX not loaded'):'ok:'+k);"
    "b.setAttribute('data-errors',window.__errors.length?window.__errors.join(' | '):'none');},1000);});</script>\n";

}   // namespace plate::report::html
