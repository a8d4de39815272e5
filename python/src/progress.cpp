// plate.Progress, and the interpreter thread's poll of a long call (interrupt.hpp).
#include "bindings.hpp"
#include "interrupt.hpp"

namespace plate::python {

bool poll_python(const py::object& progress, Watch& watch) {
    if (PyErr_CheckSignals() != 0) return false;
    Progress p;
    if (progress.is_none() || !watch.take(p)) return true;
    try {
        progress(p);
    } catch (py::error_already_set& e) {
        e.restore();
        return false;
    }
    return true;
}

void bind_progress(py::module_& m) {
    py::class_<Progress>(m, "Progress",
                         "How far a long call is: done of total units, seconds since it started, an estimate of\n"
                         "the seconds left (the mean time per unit so far times the units left; nan before the\n"
                         "first unit). A long call's progress= callable receives one every 0.05 s while it changes.")
        .def_readonly("done", &Progress::done)
        .def_readonly("total", &Progress::total)
        .def_readonly("seconds", &Progress::seconds)
        .def_readonly("seconds_left", &Progress::seconds_left)
        .def("__repr__", [](const Progress& p) {
            return "<plate.Progress " + std::to_string(p.done) + "/" + std::to_string(p.total) + ", " + num(p.seconds, 3) +
                   " s, about " + num(p.seconds_left, 3) + " s left>";
        });
}

}   // namespace plate::python
