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
        if (c == '<') o += "&lt;";
        else if (c == '>') o += "&gt;";
        else if (c == '&') o += "&amp;";
        else if (c == '"') o += "&quot;";
        else if (c == '\'') o += "&#39;";
        else o += c;
    }
    return o;
}


// gnuplot SCRIPT run in folder `dir`, stderr to `log`, without a shell (a folder's name is data, not
// a command: an apostrophe in --out once ran what followed it).
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
    std::ofstream data(const std::string& name) {
        std::ofstream o(dir / "data" / name);
        o << std::setprecision(9);
        return o;
    }
    // Runs a gnuplot script (cwd = dir) that must write `name`.svg; adds the <img>.
    void plot(const std::string& name, const std::string& script, const std::string& caption,
              const std::string& size = "640,480") {
        const fs::path gp = dir / "data" / (name + ".gp");
        std::ofstream(gp) << "set terminal svg size " << size << " dynamic background rgb 'white' font 'sans,11'\n"
                          << "set output '" << name << ".svg'\n" << script;
        if (!run_gnuplot(dir, "data/" + name + ".gp", dir / "data" / (name + ".log")) || !fs::exists(dir / (name + ".svg")))
            throw std::runtime_error("gnuplot failed on " + gp.string() + " (see data/" + name + ".log)");
        html << "<figure><img src=\"" << name << ".svg\" alt=\"" << esc(caption) << "\"><figcaption>" << caption
             << "</figcaption></figure>\n";
        ++figures;
    }
};

inline const char* kStyle = R"(<style>
body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
h1,h2,h3{color:#123}table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #bbb;padding:3px 8px;font-size:90%}
th{background:#eef}.pass{color:#080;font-weight:bold}.fail{color:#b00;font-weight:bold}figure{display:inline-block;margin:.5em}
figure img{max-width:520px;border:1px solid #ddd}figcaption{font-size:85%;max-width:520px}code,pre{background:#f6f6f6}
pre{overflow-x:auto;padding:.5em}.math{overflow-x:auto}</style>
)";

inline std::string verdict(bool ok) { return ok ? "<span class=\"pass\">pass</span>" : "<span class=\"fail\">FAIL</span>"; }


// The report's page keeps the speed-accuracy section (written by `plate bench`) between these.
inline const char* kSpeedBegin = "<!-- speed-accuracy:begin -->";
inline const char* kSpeedEnd = "<!-- speed-accuracy:end -->";

// For scripts/check-report.sh: after loading, the body says whether every image rendered.
inline const char* kImageCheck =
    "<script>window.addEventListener('load',function(){var b=[].slice.call(document.images).filter("
    "function(i){return !(i.complete&&i.naturalWidth>0);});document.body.setAttribute('data-images',"
    "b.length?'missing:'+b.map(function(i){return i.getAttribute('src');}).join(','):'ok:'+document.images.length);});"
    "</script>\n";

}  // namespace plate::report::html
