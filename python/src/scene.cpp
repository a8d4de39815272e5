// plate.Scene, plate.load_scene, plate.parse_scene and plate.Stop (why a run stopped).
#include "bindings.hpp"

namespace plate::python {

void bind_scene(py::module_& m) {
    py::class_<Scene>(m, "Scene", "A part and a periodic plate motion (a scene file's contents).")
        .def_readonly("name", &Scene::name)
        .def_readonly("source", &Scene::source)
        .def_readonly("gravity", &Scene::g)
        .def_property_readonly("point_part", [](const Scene& s) { return s.part.point; })
        .def_property_readonly("thin", [](const Scene& s) { return !s.part.point && s.part.thin(); })
        .def_property_readonly("mass", [](const Scene& s) { return s.part.m; })
        .def_property_readonly(
            "rho", [](const Scene& s) { return s.part.rho(); }, "radius of gyration sqrt(J_zz/m) [m] (1 for a point part)")
        .def_property_readonly("period", [](const Scene& s) { return s.plate.T; })
        .def_property_readonly("v_ref", &Scene::v_ref, "the slip-speed scale tolerances are relative to [m/s]")
        .def_property_readonly("warnings", &scene_warnings,
                               "admissible but outside the intended regime (the command line prints them)")
        .def(
            "to_json", [](const Scene& s) { return scene_to_json(s).dump(); }, "the scene in the file form")
        .def("__repr__", [](const Scene& s) {
            return "<plate.Scene '" + s.name + "' " +
                   (s.part.point    ? "point part"
                    : s.part.thin() ? "thin part"
                                    : "thick part") +
                   ", T = " + std::to_string(s.plate.T) + " s, " + std::to_string(s.plate.harmonics.size()) + " harmonics>";
        });
    m.def("load_scene", &load_scene, py::arg("path"), "Reads a scene file (raises plate.InputError).");
    m.def("parse_scene", &parse_scene, py::arg("text"), py::arg("source"),
          "Reads a scene from JSON text; `source` names it in messages (raises plate.InputError).");

    py::class_<PyStop>(m, "Stop", "Why a run stopped: reason 'none' if it did not.")
        .def_readonly("reason", &PyStop::reason)
        .def_readonly("contact", &PyStop::contact, "1-based; 0 if no contact is concerned")
        .def_readonly("t", &PyStop::t, "[s]")
        .def_readonly("message", &PyStop::message)
        .def("__bool__", [](const PyStop& s) { return s.reason != "none"; })
        .def("__repr__",
             [](const PyStop& s) { return "<plate.Stop " + s.reason + (s.message.empty() ? "" : ": " + s.message) + ">"; });
}

}   // namespace plate::python
