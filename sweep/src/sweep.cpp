// Running a campaign: each case computed into its row (run_case), the journal that makes a killed run
// resume, the tables (CSV, JSON lines, timing, summary SVG) and run_sweep over a farm. Reading the
// campaign file: campaign.cpp.
#include "plate/sweep.hpp"

#include "plate/farm.hpp"
#include "plate/output.hpp"
#include "plate/progress.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

namespace plate::sweep {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double num_or_nan(double x) { return std::isfinite(x) ? x : kNaN; }

}   // namespace

Row run_case(const Campaign& c, int index) {
    Row row;
    row["case"] = index;
    const std::vector<double> v = case_values(c, index);
    for (std::size_t p = 0; p < v.size(); ++p) row[c.parameters[p].name] = v[p];
    row["status"] = "ok";
    row["reason"] = "";
    row["note"] = "";
    row["rhs_evaluations"] = 0;
    // Failures (the case has no answer: bad values, a cycle that did not converge, work budgets
    // spent, a design not verified) and notes (answers: where the part would fly, the twist is
    // undefined -- the model's edge, not the method's failure).
    std::vector<std::string> reasons, notes;
    long work = 0;
    // Every column present (null where not computed), in column order.
    for (const std::string& k : columns(c))
        if (!row.contains(k)) row[k] = nullptr;
    try {
        const Scene sc = case_scene(c, index);
        const bool point = sc.part.point;
        for (std::size_t k = 0; k < c.twist_at.size(); ++k) {
            const std::string t = "twist" + std::to_string(k) + "_";
            const LimitCycleSummary lc = limit_cycle(sc, c.twist_at[k], c.cycle);
            work += lc.stats.rhs_evals;
            row[t + "vx"] = num_or_nan(lc.twist[0]);
            row[t + "vy"] = num_or_nan(lc.twist[1]);
            if (!point) row[t + "omega"] = num_or_nan(lc.twist[2]);
            row[t + "stick"] = *std::max_element(lc.stick_fraction.begin(), lc.stick_fraction.end());
            if (!lc.converged)
                (lc.stop.reason == StopReason::ContactLost ? notes : reasons)
                    .push_back("twist at configuration " + std::to_string(k) + ": " + stop_name(lc.stop.reason));
        }
        if (c.field) {
            FieldOptions fo;
            fo.cycle = c.cycle;
            fo.threads = 1;   // one case, one thread: the farm shares the cases
            const Field f = compute_field(sc, c.grid, fo);
            work += f.rhs_evals;
            int defined = 0, lost = 0;
            double speed = 0, max_speed = 0, omega = 0, stick = 0;
            for (const FieldPoint& p : f.points) {
                if (!p.converged || !p.twist.allFinite()) {
                    lost += p.stop == StopReason::ContactLost;
                    continue;
                }
                ++defined;
                const double s = p.twist.head<2>().norm();
                speed += s;
                max_speed = std::max(max_speed, s);
                omega += std::abs(p.twist[2]);
                stick += *std::max_element(p.stick_fraction.begin(), p.stick_fraction.end());
            }
            const int n = static_cast<int>(f.points.size());
            row["field_defined"] = defined;
            row["field_contact_lost"] = lost;
            row["field_unconverged"] = n - defined - lost;
            const double m = defined ? 1.0 / defined : kNaN;
            row["field_mean_speed"] = num_or_nan(speed * m);
            row["field_max_speed"] = defined ? max_speed : kNaN;
            if (!point) row["field_mean_abs_omega"] = num_or_nan(omega * m);
            row["field_mean_stick"] = num_or_nan(stick * m);
            if (lost > 0)
                notes.push_back("contact lost at " + std::to_string(lost) + " of " + std::to_string(n) + " field configurations");
            if (defined + lost < n)
                reasons.push_back(std::to_string(n - defined - lost) + " of " + std::to_string(n) +
                                  " field configurations without a cycle");
            if (c.fixed_points) {
                FixedPointOptions fpo;
                fpo.cycle = c.cycle;
                const FixedPoints fp = find_fixed_points(sc, f, fpo);
                work += fp.rhs_evaluations;
                int count[4] = {0, 0, 0, 0};
                for (const FixedPoint& p : fp.points) ++count[static_cast<int>(p.stability)];
                row["fp_stable"] = count[static_cast<int>(Stability::Stable)];
                row["fp_saddle"] = count[static_cast<int>(Stability::Saddle)];
                row["fp_unstable"] = count[static_cast<int>(Stability::Unstable)];
                row["fp_lines"] = static_cast<int>(fp.lines.size());
                row["fp_undefined_cells"] = fp.undefined_cells;
                // The stable point nearest the grid's centre (a campaign follows one point across cases).
                const Vec2 centre((c.grid.x0 + c.grid.x1) / 2, (c.grid.y0 + c.grid.y1) / 2);
                const FixedPoint* best = nullptr;
                for (const FixedPoint& p : fp.points)
                    if (p.stability == Stability::Stable &&
                        (!best || (p.q.head<2>() - centre).norm() < (best->q.head<2>() - centre).norm()))
                        best = &p;
                if (best) {
                    row["stable_x"] = best->q[0];
                    row["stable_y"] = best->q[1];
                    if (!point) row["stable_theta"] = best->q[2];
                    double re = -std::numeric_limits<double>::infinity();
                    for (int i = 0; i < (point ? 2 : 3); ++i) re = std::max(re, best->eigenvalues[i].real());
                    row["stable_rate"] = -re;   // the slowest direction's convergence rate [1/s]
                }
                row["fp_summary"] = fixed_points_sentence(fp);
                row["fixed_points"] = Row::parse(to_json(sc, fp)["points"].dump());
                if (fp.unsearched_cells > 0) reasons.push_back("fixed points: the refinement's work budget was spent");
            }
        }
        if (c.design) {
            const DesignSummary d = design(sc, *c.design, c.design_options);
            row["design_verified"] = d.verified;
            row["design_unique"] = d.unique;
            row["design_x"] = d.fixed_point[0];
            row["design_y"] = d.fixed_point[1];
            row["design_rate"] = d.rate;
            row["design_worst_end_distance"] = d.worst_end_distance;
            row["design_evaluations"] = d.evaluations;
            if (!d.verified) reasons.push_back("design: " + d.failure);
        }
    } catch (const Interrupted&) {   // (asked to stop: no row, the case stays out of the journal)
        throw;
    } catch (const std::exception& e) {   // (the values make the scene invalid; a design's target)
        reasons.push_back(e.what());
    }
    row["rhs_evaluations"] = work;
    auto join = [](const std::vector<std::string>& v) {
        std::string r;
        for (const auto& x : v) r += (r.empty() ? "" : "; ") + x;
        return r;
    };
    row["note"] = join(notes);
    if (!reasons.empty()) {
        row["status"] = "failed";
        row["reason"] = join(reasons);
    }
    return row;
}

// ---- the journal ------------------------------------------------------------------------------

std::string journal_line(int index, int rank, double seconds, const Row& row) {
    Row e;
    e["case"] = index;
    e["rank"] = rank;
    e["seconds"] = seconds;
    e["row"] = row;
    return e.dump();
}

namespace {
// write(2) until all is written.
void write_all(int fd, const std::string& s, const std::string& path) {
    std::size_t off = 0;
    while (off < s.size()) {
        const ssize_t n = ::write(fd, s.data() + off, s.size() - off);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw std::runtime_error(path + ": write failed: " + std::strerror(errno));
        off += static_cast<std::size_t>(n);
    }
}
void sync_dir(const fs::path& dir) {
    const int d = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
    if (d >= 0) {
        ::fsync(d);
        ::close(d);
    }
}
json journal_header(const Campaign& c) {
    return {{"journal", "plate sweep"}, {"campaign", c.name}, {"fingerprint", fingerprint(c)}, {"cases", c.cases()}};
}
}   // namespace

Journal::Journal(const std::string& dir, const Campaign& c) : done_(static_cast<std::size_t>(c.cases()), 0) {
    try {
        open(dir, c);
    } catch (...) {   // (the destructor does not run for a constructor that throws: release the lock here)
        if (fd_ >= 0) ::close(fd_);
        if (lock_ >= 0) ::close(lock_);
        throw;
    }
}

void Journal::open(const std::string& dir, const Campaign& c) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir)) throw InputError(dir + ": cannot create the output folder");
    const std::string lock = (fs::path(dir) / "journal.lock").string();
    lock_ = ::open(lock.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
    if (lock_ < 0) throw InputError(lock + ": cannot open: " + std::strerror(errno));
    if (::flock(lock_, LOCK_EX | LOCK_NB) != 0)
        throw InputError(dir + ": another plate sweep is writing this folder (" + lock + " is locked)");
    path_ = (fs::path(dir) / "journal.jsonl").string();
    const std::string header = journal_header(c).dump();
    std::string text;
    if (fs::exists(path_)) {
        std::ifstream in(path_, std::ios::binary);
        std::stringstream s;
        s << in.rdbuf();
        text = s.str();
    }
    // The complete lines: the header, then entries. A last line without its newline, or one that
    // does not parse, is torn (the writer was killed in it) and cut off.
    std::size_t good = 0, pos = 0;
    int line_no = 0;
    while (pos < text.size()) {
        const std::size_t nl = text.find('\n', pos);
        const bool last = nl == std::string::npos || nl + 1 == text.size();
        const std::string line = text.substr(pos, nl == std::string::npos ? std::string::npos : nl - pos);
        ++line_no;
        Row e;
        bool ok = nl != std::string::npos;
        if (ok) {
            try {
                e = Row::parse(line);
            } catch (const json::exception&) {
                ok = false;
            }
        }
        if (!ok) {
            if (!last)
                throw InputError(path_ + ":" + std::to_string(line_no) +
                                 ": not a journal line (the journal is damaged; remove it to start again)");
            ++dropped_;
            break;
        }
        if (line_no == 1) {
            if (!e.is_object() || e.value("journal", "") != "plate sweep")
                throw InputError(path_ + ": not a plate sweep journal");
            if (e.value("fingerprint", "") != fingerprint(c))
                throw InputError(path_ + ": the journal of another campaign ('" + e.value("campaign", "?") + "', fingerprint " +
                                 e.value("fingerprint", "?") + "; this one's is " + fingerprint(c) +
                                 "): use another --out folder, or remove the journal to start again");
        } else {
            Entry en;
            try {
                en.index = e.at("case").get<int>();
                en.rank = e.at("rank").get<int>();
                en.seconds = e.at("seconds").get<double>();
                en.row = e.at("row");
            } catch (const json::exception&) {
                throw InputError(path_ + ":" + std::to_string(line_no) + ": a journal line without case, rank, seconds or row");
            }
            if (!(en.index >= 0 && en.index < c.cases()) || done_[static_cast<std::size_t>(en.index)])
                throw InputError(path_ + ":" + std::to_string(line_no) + ": case " + std::to_string(en.index) +
                                 " out of range or twice (the journal is damaged; remove it to start again)");
            done_[static_cast<std::size_t>(en.index)] = 1;
            entries_.push_back(std::move(en));
        }
        good = nl + 1;
        pos = nl + 1;
    }
    resumed_ = static_cast<int>(entries_.size());
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw InputError(path_ + ": cannot open for writing: " + std::strerror(errno));
    if (::ftruncate(fd_, static_cast<off_t>(good)) != 0 || ::lseek(fd_, 0, SEEK_END) < 0)
        throw InputError(path_ + ": cannot cut the torn last line: " + std::strerror(errno));
    if (good == 0) {
        write_all(fd_, header + "\n", path_);
        ::fsync(fd_);
        sync_dir(fs::path(dir));
    } else if (dropped_) {
        ::fsync(fd_);
    }
}

Journal::~Journal() {
    if (fd_ >= 0) ::close(fd_);
    if (lock_ >= 0) ::close(lock_);   // (releases the flock)
}

void Journal::append(const std::string& line) {
    Entry en;
    const Row e = Row::parse(line);
    en.index = e.at("case").get<int>();
    en.rank = e.at("rank").get<int>();
    en.seconds = e.at("seconds").get<double>();
    en.row = e.at("row");
    if (done(en.index)) return;   // (never sent twice; kept idempotent)
    write_all(fd_, line + "\n", path_);
    if (::fdatasync(fd_) != 0) throw std::runtime_error(path_ + ": fdatasync failed: " + std::strerror(errno));
    done_[static_cast<std::size_t>(en.index)] = 1;
    entries_.push_back(std::move(en));
}

// ---- the tables ---------------------------------------------------------------------------------

namespace {

std::string csv_cell(const Row& v) {
    if (v.is_null()) return "";
    if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
    if (v.is_number_integer() || v.is_number_unsigned()) return v.dump();
    if (v.is_number_float()) {
        return shortest(v.get<double>());
    }
    const std::string s = v.is_string() ? v.get<std::string>() : v.dump();
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string q = "\"";
    for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return q + "\"";
}

// Sequential colours (light yellow to dark blue) for t in [0, 1].
std::string colour(double t) {
    static const double stops[5][3] = {{255, 255, 204}, {161, 218, 180}, {65, 182, 196}, {44, 127, 184}, {37, 52, 148}};
    t = std::clamp(t, 0.0, 1.0) * 4;
    const int i = std::min(3, static_cast<int>(t));
    const double f = t - i;
    char buf[8];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", static_cast<int>(stops[i][0] + f * (stops[i + 1][0] - stops[i][0])),
                  static_cast<int>(stops[i][1] + f * (stops[i + 1][1] - stops[i][1])),
                  static_cast<int>(stops[i][2] + f * (stops[i + 1][2] - stops[i][2])));
    return buf;
}

std::string svg_num(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", x);
    return buf;
}

std::string xml(const std::string& s) {
    std::string o;
    for (char ch : s) {
        if (ch == '<')
            o += "&lt;";
        else if (ch == '>')
            o += "&gt;";
        else if (ch == '&')
            o += "&amp;";
        else
            o += ch;
    }
    return o;
}

// The summary figure: two panels over the first two parameters (one: a strip), each case a cell
// (grid sampling) or a dot (random), coloured by a result; failed cases crossed.
std::string summary_svg(const Campaign& c, const std::vector<const Row*>& rows) {
    struct Panel {
        std::string title;
        std::function<double(const Row&)> value;
    };
    auto get = [](const Row& r, const std::string& k) { return r.contains(k) && r[k].is_number() ? r[k].get<double>() : kNaN; };
    std::vector<Panel> panels;
    if (c.fixed_points) {
        panels.push_back({"stable fixed points found", [=](const Row& r) { return get(r, "fp_stable"); }});
        panels.push_back({"convergence rate of the stable point nearest the centre [1/s]",
                          [=](const Row& r) { return get(r, "stable_rate"); }});
    } else if (c.field) {
        panels.push_back({"mean speed over the field [mm/s]", [=](const Row& r) { return 1e3 * get(r, "field_mean_speed"); }});
        panels.push_back({"mean stick fraction over the field", [=](const Row& r) { return get(r, "field_mean_stick"); }});
    } else if (!c.twist_at.empty()) {
        panels.push_back({"speed at configuration 0 [mm/s]",
                          [=](const Row& r) { return 1e3 * std::hypot(get(r, "twist0_vx"), get(r, "twist0_vy")); }});
        panels.push_back({"stick fraction at configuration 0", [=](const Row& r) { return get(r, "twist0_stick"); }});
    } else {
        panels.push_back({"design verified (1) or not (0)", [=](const Row& r) {
                              return r["design_verified"].is_boolean() ? (r["design_verified"].get<bool>() ? 1.0 : 0.0) : kNaN;
                          }});
        panels.push_back({"design's convergence rate [1/s]", [=](const Row& r) { return get(r, "design_rate"); }});
    }
    const int W = 1120, H = 520, pw = 400, ph = 360, top = 70, left0 = 90;
    const bool two = c.parameters.size() >= 2;
    std::ostringstream s;
    s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W << " " << H
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    s << "<text x=\"" << W / 2 << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">" << xml(c.name) << ": " << rows.size()
      << " cases</text>\n";
    auto axis_range = [&](std::size_t p) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const Row* r : rows) {
            const double x = (*r)[c.parameters[p].name].get<double>();
            lo = std::min(lo, x);
            hi = std::max(hi, x);
        }
        return std::make_pair(lo, hi);
    };
    const auto xr = axis_range(0);
    const auto yr = two ? axis_range(1) : std::make_pair(0.0, 0.0);
    const int nx = c.random ? 0 : static_cast<int>(c.parameters[0].values.size());
    const int ny = c.random || !two ? 1 : static_cast<int>(c.parameters[1].values.size());
    for (std::size_t k = 0; k < panels.size(); ++k) {
        const int x0 = left0 + static_cast<int>(k) * (pw + 120), y0 = top;
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        std::vector<double> val;
        for (const Row* r : rows) {
            const double v = panels[k].value(*r);
            val.push_back(v);
            if (std::isfinite(v)) {
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
        }
        if (!(hi > lo)) hi = lo + 1;
        if (!std::isfinite(lo)) lo = 0, hi = 1;
        s << "<text x=\"" << x0 + pw / 2 << "\" y=\"" << y0 - 12 << "\" text-anchor=\"middle\">" << xml(panels[k].title)
          << "</text>\n";
        s << "<rect x=\"" << x0 << "\" y=\"" << y0 << "\" width=\"" << pw << "\" height=\"" << ph
          << "\" fill=\"#eee\" stroke=\"#888\"/>\n";
        auto X = [&](double x) { return x0 + (xr.second > xr.first ? (x - xr.first) / (xr.second - xr.first) : 0.5) * pw; };
        auto Y = [&](double y) { return y0 + ph - (yr.second > yr.first ? (y - yr.first) / (yr.second - yr.first) : 0.5) * ph; };
        for (std::size_t i = 0; i < rows.size(); ++i) {
            const Row& r = *rows[i];
            const double px = r[c.parameters[0].name].get<double>(), py = two ? r[c.parameters[1].name].get<double>() : 0.0;
            const std::string fill = std::isfinite(val[i]) ? colour((val[i] - lo) / (hi - lo)) : "#bbbbbb";
            const bool failed = r["status"] != "ok";
            double cx, cy, cw, ch;
            if (c.random) {
                cx = X(px);
                cy = Y(py);
                s << "<circle cx=\"" << cx << "\" cy=\"" << cy << "\" r=\"4\" fill=\"" << fill
                  << "\" stroke=\"#333\" stroke-width=\"0.5\"/>\n";
                cw = ch = 8;
            } else {
                const int idx = r["case"].get<int>();
                const int iy = two ? (idx / static_cast<int>(c.cases() / (nx * ny))) % ny : 0;
                const int ix = (idx / static_cast<int>(c.cases() / nx)) % nx;
                cw = static_cast<double>(pw) / nx;
                ch = static_cast<double>(ph) / ny;
                cx = x0 + (ix + 0.5) * cw;
                cy = y0 + ph - (iy + 0.5) * ch;
                s << "<rect x=\"" << x0 + ix * cw << "\" y=\"" << y0 + ph - (iy + 1) * ch << "\" width=\"" << cw << "\" height=\""
                  << ch << "\" fill=\"" << fill << "\"><title>case " << idx << ": " << svg_num(val[i]) << "</title></rect>\n";
            }
            if (failed)
                s << "<path d=\"M" << cx - cw / 4 << " " << cy - ch / 4 << "L" << cx + cw / 4 << " " << cy + ch / 4 << "M"
                  << cx - cw / 4 << " " << cy + ch / 4 << "L" << cx + cw / 4 << " " << cy - ch / 4
                  << "\" stroke=\"#900\" stroke-width=\"1.2\"/>\n";
        }
        // Axes: the parameters' ranges; a colour bar with the value range.
        s << "<text x=\"" << x0 << "\" y=\"" << y0 + ph + 16 << "\">" << svg_num(xr.first) << "</text>\n"
          << "<text x=\"" << x0 + pw << "\" y=\"" << y0 + ph + 16 << "\" text-anchor=\"end\">" << svg_num(xr.second)
          << "</text>\n"
          << "<text x=\"" << x0 + pw / 2 << "\" y=\"" << y0 + ph + 32 << "\" text-anchor=\"middle\">" << xml(c.parameters[0].name)
          << "</text>\n";
        if (two)
            s << "<text x=\"" << x0 - 6 << "\" y=\"" << y0 + ph << "\" text-anchor=\"end\">" << svg_num(yr.first) << "</text>\n"
              << "<text x=\"" << x0 - 6 << "\" y=\"" << y0 + 10 << "\" text-anchor=\"end\">" << svg_num(yr.second) << "</text>\n"
              << "<text transform=\"translate(" << x0 - 50 << "," << y0 + ph / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
              << xml(c.parameters[1].name) << "</text>\n";
        const int bx = x0 + pw + 10;
        for (int b = 0; b < 40; ++b)
            s << "<rect x=\"" << bx << "\" y=\"" << y0 + ph - (b + 1) * ph / 40.0 << "\" width=\"14\" height=\""
              << ph / 40.0 + 0.5 << "\" fill=\"" << colour((b + 0.5) / 40) << "\"/>\n";
        s << "<text x=\"" << bx + 18 << "\" y=\"" << y0 + ph << "\">" << svg_num(lo) << "</text>\n<text x=\"" << bx + 18
          << "\" y=\"" << y0 + 10 << "\">" << svg_num(hi) << "</text>\n";
    }
    s << "<text x=\"" << left0 << "\" y=\"" << H - 14
      << "\" fill=\"#555\">grey: no value; red cross: the case failed (see its reason in "
      << "table.csv)</text>\n</svg>\n";
    return s.str();
}

}   // namespace

void write_tables(const std::string& dir, const Campaign& c, const Journal& j) {
    std::vector<const Journal::Entry*> by_case(static_cast<std::size_t>(c.cases()), nullptr);
    for (const auto& e : j.entries()) by_case[static_cast<std::size_t>(e.index)] = &e;
    for (std::size_t i = 0; i < by_case.size(); ++i)
        if (!by_case[i]) throw std::logic_error("write_tables: case " + std::to_string(i) + " is not in the journal");
    const std::vector<std::string> col = columns(c);
    const fs::path d(dir);
    write_file_atomic((d / "table.csv").string(), [&](std::ostream& o) {
        for (std::size_t k = 0; k < col.size(); ++k) o << (k ? "," : "") << csv_cell(Row(column_heading(c, col[k])));
        o << "\n";
        for (const auto* e : by_case) {
            for (std::size_t k = 0; k < col.size(); ++k)
                o << (k ? "," : "") << csv_cell(e->row.contains(col[k]) ? e->row[col[k]] : Row());
            o << "\n";
        }
    });
    write_file_atomic((d / "table.jsonl").string(), [&](std::ostream& o) {
        for (const auto* e : by_case) o << e->row.dump() << "\n";
    });
    write_file_atomic((d / "timing.csv").string(), [&](std::ostream& o) {
        o << "case,rank,seconds [s],rhs_evaluations\n";
        for (const auto* e : by_case)
            o << e->index << "," << e->rank << "," << csv_cell(Row(e->seconds)) << "," << csv_cell(e->row["rhs_evaluations"])
              << "\n";
    });
    std::vector<const Row*> rows;
    for (const auto* e : by_case) rows.push_back(&e->row);
    write_file_atomic((d / "summary.svg").string(), [&](std::ostream& o) { o << summary_svg(c, rows); });
}

// ---- running -------------------------------------------------------------------------------------

nlohmann::json sweep_summary_json(const std::string& campaign_file, const std::string& out, const SweepSummary& s) {
    return {{"campaign", campaign_file},
            {"out", out},
            {"cases", s.cases},
            {"resumed", s.resumed},
            {"computed", s.computed},
            {"failed", s.failed},
            {"torn_journal_lines_dropped", s.torn},
            {"seconds", s.seconds},
            {"busy_seconds", s.busy_seconds},
            {"workers", s.workers},
            {"farm", s.farm},
            {"load_balance_efficiency", s.computed && s.seconds > 0 ? s.busy_seconds / (s.seconds * s.workers) : 0.0},
            {"tables", {out + "/table.csv", out + "/table.jsonl"}}};
}

SweepSummary run_sweep(const std::string& campaign_file, const SweepOptions& opt, Farm& farm) {
    const auto t0 = std::chrono::steady_clock::now();
    SweepSummary s;
    // Rank 0 reads the files and opens the journal; the others get the campaign (or the news of
    // an error, which rank 0 reports).
    std::unique_ptr<Journal> journal;
    Campaign c;
    std::string text;
    if (farm.root()) {
        try {
            c = load_campaign(campaign_file);
            journal = std::make_unique<Journal>(opt.out, c);
            text = "ok\n" + c.file.dump();
        } catch (const InputError& e) {
            text = "error\n";
            farm.broadcast(text);
            throw;
        }
    }
    farm.broadcast(text);
    if (!farm.root()) {
        if (text.rfind("ok\n", 0) != 0) throw Reported("rank 0 reported an error");
        c = campaign_from_json(json::parse(text.substr(3)), campaign_file);
    }
    s.cases = c.cases();
    std::vector<int> todo;
    if (farm.root()) {
        s.resumed = journal->resumed();
        s.torn = journal->dropped();
        for (int i = 0; i < s.cases; ++i)
            if (!journal->done(i)) todo.push_back(i);
    }
    std::atomic<int> finished{0};
    // Test hook (tests/sweep/check_sweep.py): each case takes at least this long [s], so that a test
    // can kill a run in the middle, whatever the machine's speed.
    const char* delay_env = std::getenv("PLATE_TEST_SWEEP_CASE_DELAY");
    const double delay = delay_env ? std::atof(delay_env) : 0.0;
    auto work = [&](int i) {
        const auto a = std::chrono::steady_clock::now();
        const Row row = run_case(c, i);
        if (delay > 0) std::this_thread::sleep_for(std::chrono::duration<double>(delay));
        const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
        return journal_line(i, farm.rank(), sec, row);
    };
    auto done = [&](int, const std::string& line) {
        journal->append(line);
        const int n = ++finished;
        if (opt.progress) opt.progress(s.resumed + n, s.cases);
    };
    farm.run(todo, work, done);
    s.workers = farm.workers();
    s.farm = farm.describe();
    if (!farm.root()) return s;
    s.computed = finished;
    for (const auto& e : journal->entries()) {
        if (e.row["status"] != "ok") ++s.failed;
    }
    for (std::size_t k = static_cast<std::size_t>(s.resumed); k < journal->entries().size(); ++k)
        s.busy_seconds += journal->entries()[k].seconds;
    write_tables(opt.out, c, *journal);
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return s;
}

}   // namespace plate::sweep
