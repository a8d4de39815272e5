// plate.Scene, plate.load_scene, plate.parse_scene and plate.Stop (why a run stopped).
#include "bindings.hpp"

#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <filesystem>

#include "plate/friction.hpp"

namespace plate::python {

namespace {

// Scene attributes are set through the file form: the value (numbers, lists, dicts as in a scene file;
// numpy arrays as lists) replaces the field at `pointer`, and the whole scene is checked again as a file
// is (plate.InputError naming the field; the scene unchanged then).
void set_field(Scene& s, const char* pointer, py::object v) {
    std::string field = pointer + 1;   // ("part/mass" -> "part.mass", as the file's messages name it)
    std::replace(field.begin(), field.end(), '/', '.');
    const std::string where = (s.source.empty() ? std::string("the scene") : s.source) + " (" + field + " set)";
    if (s.part.point && (field == "part.contacts" || field == "part.inertia"))
        throw InputError(where + ": " + field +
                         ": a point part has no contacts or inertia (a rigid part: plate.Scene(part=...))");
    if (py::hasattr(v, "tolist")) v = v.attr("tolist")();
    nlohmann::json j = scene_to_json(s);
    j[nlohmann::json::json_pointer(pointer)] =
        nlohmann::json::parse(py::module_::import("json").attr("dumps")(v).cast<std::string>());
    const std::string source = s.source;
    Scene changed = parse_scene(j.dump(), where);
    changed.source = source;
    s = std::move(changed);
}

}   // namespace

void bind_scene(py::module_& m) {
    py::class_<Scene>(m, "Scene", "A part and a periodic plate motion (a scene file's contents).")
        .def(py::init([](const py::dict& part, const py::dict& plate, const std::string& name, double gravity) {
                 py::dict d;
                 d["name"] = name;
                 d["gravity"] = gravity;
                 d["part"] = part;
                 d["plate"] = plate;
                 const std::string text = py::module_::import("json").attr("dumps")(d).cast<std::string>();
                 return parse_scene(text, "plate.Scene(...)");
             }),
             py::kw_only(), py::arg("part"), py::arg("plate"), py::arg("name") = "scene", py::arg("gravity") = 9.81,
             "A scene from its part and plate motion in the scene file's form, e.g. part={'mass': 0.02, 'friction': "
             "0.3},\nplate={'period': 0.05, 'harmonics': [{'axis': 'x', 'n': 1, 'amp': 20, 'phase': 0}]}; checked as a "
             "file is\n(raises plate.InputError naming the field).")
        .def_property(
            "name", [](const Scene& s) { return s.name; }, [](Scene& s, py::object v) { set_field(s, "/name", std::move(v)); })
        .def_readonly("source", &Scene::source)
        .def_property(
            "gravity", [](const Scene& s) { return s.g; }, [](Scene& s, py::object v) { set_field(s, "/gravity", std::move(v)); },
            "[m/s^2]")
        .def_property_readonly("point_part", [](const Scene& s) { return s.part.point; })
        .def_property_readonly("thin", [](const Scene& s) { return !s.part.point && s.part.thin(); })
        .def_property(
            "mass", [](const Scene& s) { return s.part.m; },
            [](Scene& s, py::object v) { set_field(s, "/part/mass", std::move(v)); }, "[kg]")
        .def_property_readonly(
            "rho", [](const Scene& s) { return s.part.rho(); }, "radius of gyration sqrt(J_zz/m) [m] (1 for a point part)")
        .def_property(
            "period", [](const Scene& s) { return s.plate.T; },
            [](Scene& s, py::object v) { set_field(s, "/plate/period", std::move(v)); }, "[s]")
        .def_property_readonly("v_ref", &Scene::v_ref, "the slip-speed scale tolerances are relative to [m/s]")
        .def_property_readonly("warnings", &scene_warnings,
                               "admissible but outside the intended regime (the command line prints them)")
        .def_property(
            "inertia", [](const Scene& s) -> py::object { return s.part.point ? py::object(py::none()) : py::cast(s.part.J); },
            [](Scene& s, py::object v) { set_field(s, "/part/inertia", std::move(v)); },
            "J, the rotational inertia about the centre of mass in the part's frame S, (3, 3) [kg m^2]; None for a point part")
        .def_property(
            "contacts",
            [](const Scene& s) -> py::object {
                if (s.part.point) return py::none();
                Eigen::Matrix3d c;
                for (int i = 0; i < 3; ++i) c.row(i) = s.part.c[i].transpose();
                return py::cast(c);
            },
            [](Scene& s, py::object v) { set_field(s, "/part/contacts", std::move(v)); },
            "the contacts c_i in S, one per row, (3, 3) [m]; None for a point part")
        .def_property(
            "friction",
            [](const Scene& s) {
                const ContactFriction f = s.part.friction();
                py::list kinetic, static_;
                for (int i = 0; i < s.part.contacts(); ++i) {
                    kinetic.append(f.kinetic()[i]);
                    static_.append(f.static_()[i]);
                }
                py::dict d;
                d["kinetic"] = kinetic;
                d["static"] = static_;
                return d;
            },
            [](Scene& s, py::object v) { set_field(s, "/part/friction", std::move(v)); },
            "{'kinetic': [mu_k per contact], 'static': [mu_s per contact]} (one each for a point part); set as in a "
            "scene file: a number or a list sets both static and kinetic to it (mu_s = mu_k)")
        .def_property(
            "harmonics",
            [](const Scene& s) {
                py::list l;
                for (const Harmonic& h : s.plate.harmonics)
                    l.append(py::dict(py::arg("axis") = axis_name(h.axis), py::arg("n") = h.n, py::arg("amp") = h.amp,
                                      py::arg("phase") = h.phase));
                return l;
            },
            [](Scene& s, py::object v) { set_field(s, "/plate/harmonics", std::move(v)); },
            "the plate's u(t) = sum of amp sin(n 2 pi t / T + phase) per axis: [{'axis', 'n', 'amp' [m/s^2 or "
            "rad/s^2], 'phase' [rad]}]")
        .def(
            "to_json", [](const Scene& s) { return scene_to_json(s).dump(); }, "the scene in the file form")
        // Equal: the same file form (name, gravity, part, plate motion), wherever each was read from.
        .def(
            "__eq__", [](const Scene& a, const Scene& b) { return scene_to_json(a) == scene_to_json(b); }, py::is_operator())
        .def("__copy__", [](const Scene& s) { return Scene(s); })
        .def(
            "__deepcopy__", [](const Scene& s, py::dict) { return Scene(s); }, py::arg("memo"))
        // Pickled as the file form (whose numbers read back to the same doubles) and the source.
        .def(py::pickle([](const Scene& s) { return py::make_tuple(scene_to_json(s).dump(), s.source); },
                        [](const py::tuple& t) {
                            require(t.size() == 2, "plate.Scene: a pickled scene is (file text, source)");
                            return parse_scene(t[0].cast<std::string>(), t[1].cast<std::string>());
                        }))
        .def("__repr__", [](const Scene& s) {
            return "<plate.Scene '" + s.name + "' " +
                   (s.part.point    ? "point part"
                    : s.part.thin() ? "thin part"
                                    : "thick part") +
                   ", T = " + std::to_string(s.plate.T) + " s, " + std::to_string(s.plate.harmonics.size()) + " harmonics>";
        });
    m.def(
        "load_scene", [](const std::filesystem::path& p) { return load_scene(p.string()); }, py::arg("path"),
        "Reads a scene file, its path a str or os.PathLike (raises plate.InputError).");
    m.def("parse_scene", &parse_scene, py::arg("text"), py::arg("source"),
          "Reads a scene from JSON text; `source` names it in messages (raises plate.InputError).");

    py::class_<PyStop>(m, "Stop", "Why a run stopped: reason 'none' if it did not.")
        .def_readonly("reason", &PyStop::reason)
        .def_readonly("contact", &PyStop::contact, "1-based; 0 if no contact is concerned")
        .def_readonly("t", &PyStop::t, "[s]")
        .def_readonly("message", &PyStop::message)
        .def("__bool__", [](const PyStop& s) { return s.reason != "none"; })
        .def(py::pickle(
            [](const PyStop& s) { return py::make_tuple(s.reason, s.contact, s.t, s.message); },
            [](const py::tuple& t) {
                require(t.size() == 4, "plate.Stop: not a pickled stop");
                return PyStop{t[0].cast<std::string>(), t[1].cast<int>(), t[2].cast<double>(), t[3].cast<std::string>()};
            }))
        .def("__repr__",
             [](const PyStop& s) { return "<plate.Stop " + s.reason + (s.message.empty() ? "" : ": " + s.message) + ">"; });
}

}   // namespace plate::python
