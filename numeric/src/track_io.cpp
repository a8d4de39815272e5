// The track file (observe.hpp): written by write_track_csv, read by parse_track_csv, each complaint
// naming the file and the line.
#include "plate/observe.hpp"

#include "plate/output.hpp"
#include "plate/scene_io.hpp"

#include "input_reader.hpp"

#include <iomanip>
#include <sstream>

namespace plate {

namespace {

constexpr int kTrackVersion = 1;
const char* const kFormatLine = "# plate track ";
const char* const kHeaderKeys[5] = {"scene", "scene_id", "camera", "frame", "part"};

std::string columns(bool point) { return point ? "t [s],s_x [m],s_y [m]" : "t [s],s_x [m],s_y [m],theta [rad]"; }

}   // namespace

void write_track_csv(std::ostream& out, const Track& tr) {
    out << kFormatLine << kTrackVersion << "\n"
        << "# scene: " << nlohmann::json(tr.scene_name).dump() << "\n"
        << "# scene_id: " << tr.scene_id << "\n"
        << "# camera: " << camera_to_json(tr.camera).dump() << "\n"
        << "# frame: " << frame_name(tr.camera.frame) << "\n"
        << "# part: " << (tr.point ? "point" : "rigid") << "\n"
        << columns(tr.point) << "\n";
    for (std::size_t k = 0; k < tr.t.size(); ++k) {
        out << shortest(tr.t[k]) << ',' << shortest(tr.q[k].x()) << ',' << shortest(tr.q[k].y());
        if (!tr.point) out << ',' << shortest(tr.q[k].z());
        out << '\n';
    }
}

namespace {

// The lines of a text (without their '\n' and a '\r' before it) and the failure of one of them.
struct Lines {
    std::string source;
    std::vector<std::string> text;
    [[noreturn]] void fail(std::size_t line, const std::string& what, int column = 0) const {
        throw InputError(source + ":" + std::to_string(line) + (column > 0 ? ":" + std::to_string(column) : "") + ": " + what);
    }
};

// The header's "# KEY: VALUE" at line i (1-based) as VALUE.
std::string header_value(const Lines& L, std::size_t i, const char* key) {
    const std::string want = std::string("# ") + key + ": ";
    const std::string expected = "expected the header line \"" + want + "...\" (format: observe.hpp)";
    if (i > L.text.size()) L.fail(i, "the file ends before the header is complete: " + expected);
    const std::string& l = L.text[i - 1];
    if (l.compare(0, want.size(), want) != 0) L.fail(i, expected + ", got \"" + detail::Reader::printable(l) + "\"");
    return l.substr(want.size());
}

}   // namespace

Track parse_track_csv(const std::string& text, const std::string& source) {
    Lines L{source, {}};
    {
        std::stringstream in(text);
        std::string l;
        while (std::getline(in, l)) {
            if (!l.empty() && l.back() == '\r') l.pop_back();
            L.text.push_back(l);
        }
    }
    const std::string format = std::string(kFormatLine) + std::to_string(kTrackVersion);
    if (L.text.empty() || L.text[0].compare(0, std::string(kFormatLine).size(), kFormatLine) != 0)
        L.fail(1, "expected the format line \"" + format + "\" (not a track file?)");
    if (L.text[0] != format)
        L.fail(1, "unknown track format version \"" +
                      detail::Reader::printable(L.text[0].substr(std::string(kFormatLine).size())) + "\" (this reader knows " +
                      std::to_string(kTrackVersion) + ")");
    Track tr;
    tr.source = source;
    std::size_t i = 2;
    const std::string name = header_value(L, i, kHeaderKeys[0]);
    try {
        const nlohmann::json j = nlohmann::json::parse(name);
        if (!j.is_string() || j.get<std::string>().empty()) throw std::invalid_argument("");
        tr.scene_name = j.get<std::string>();
    } catch (const std::exception&) {
        L.fail(i, "scene: expected the scene's name as a JSON string, e.g. \"fig4\"");
    }
    tr.scene_id = header_value(L, ++i, kHeaderKeys[1]);
    tr.scene_id_line = static_cast<int>(i);
    if (tr.scene_id.size() != 16 || tr.scene_id.find_first_not_of("0123456789abcdef") != std::string::npos)
        L.fail(i, "scene_id: expected 16 lowercase hex digits (scene_id() of the scene)");
    ++i;
    tr.camera = parse_camera(header_value(L, i, kHeaderKeys[2]), source + ":" + std::to_string(i) + ": camera");
    tr.camera.source = source + ":" + std::to_string(i);
    const std::string frame = header_value(L, ++i, kHeaderKeys[3]);
    if (frame != frame_name(tr.camera.frame))
        L.fail(i, "frame: expected \"" + std::string(frame_name(tr.camera.frame)) + "\", the camera's frame");
    const std::string part = header_value(L, ++i, kHeaderKeys[4]);
    if (part != "point" && part != "rigid") L.fail(i, "part: expected \"rigid\" or \"point\"");
    tr.point = part == "point";
    const std::string cols = columns(tr.point);
    if (++i > L.text.size() || detail::split_csv(detail::trim(L.text[i - 1])) != detail::split_csv(cols))
        L.fail(i, "expected the column line \"" + cols + "\" (a " + part + " part)");
    const std::size_t n = tr.point ? 3 : 4;
    const char* const names[4] = {"t [s]", "s_x [m]", "s_y [m]", "theta [rad]"};
    for (++i; i <= L.text.size(); ++i) {
        const std::string l = detail::trim(L.text[i - 1]);
        if (l.empty()) continue;
        const auto cells = detail::split_csv(l);
        if (cells.size() != n)
            L.fail(i, "expected " + std::to_string(n) + " columns (" + cols + "), got " + std::to_string(cells.size()));
        double v[4] = {0, 0, 0, 0};
        for (std::size_t k = 0; k < n; ++k)
            if (!detail::finite_number(cells[k], v[k]))
                L.fail(i,
                       std::string(names[k]) + ": expected a finite number, got \"" + detail::Reader::printable(cells[k]) + "\"",
                       static_cast<int>(k) + 1);
        if (!tr.t.empty() && !(v[0] > tr.t.back()))
            L.fail(i,
                   "t [s]: expected a time after the previous frame's " + detail::Reader::fmt(tr.t.back()) + " s, got " +
                       detail::Reader::fmt(v[0]),
                   1);
        tr.t.push_back(v[0]);
        tr.q.emplace_back(v[1], v[2], v[3]);
        tr.lines.push_back(static_cast<int>(i));
    }
    if (tr.t.size() < static_cast<std::size_t>(kMinTrackFrames))
        L.fail(L.text.size(), std::to_string(tr.t.size()) + " frames: a track needs at least " + std::to_string(kMinTrackFrames) +
                                  " (a velocity needs two positions, an acceleration three)");
    return tr;
}

Track read_track_csv(const std::string& path) { return parse_track_csv(detail::read_input_file(path, "track file"), path); }

void check_track_scene(const Track& track, const Scene& scene) {
    const std::string id = scene_id(scene);
    if (track.scene_id == id) return;
    throw InputError((track.source.empty() ? std::string("(track)") : track.source) +
                     (track.scene_id_line > 0 ? ":" + std::to_string(track.scene_id_line) : std::string()) +
                     ": tracks from another scene: taken under \"" + detail::Reader::printable(track.scene_name) +
                     "\" (scene_id " + track.scene_id + "), not under " +
                     (scene.source.empty() ? std::string() : scene.source + "'s ") + "\"" +
                     detail::Reader::printable(scene.name) + "\" (scene_id " + id + ")");
}

}   // namespace plate
