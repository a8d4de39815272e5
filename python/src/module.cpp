// The Python module `plate` (its compiled half, plate._plate; python/plate/__init__.py is the rest).
//
// What the command line computes, callable from a notebook: scenes from files or dicts, asymptotic
// twists (limit cycles), fields as numpy arrays over their grid, fixed points, trajectories with the
// contact mode of every sample. Options are keyword arguments with the library's defaults; results
// are objects whose arrays are numpy arrays, and whose `summary` is the command line's JSON as a dict.
// The GIL is released while the library works (fields and long simulations take seconds), so other
// Python threads run meanwhile; long calls stop on Ctrl-C and report progress (interrupt.hpp). Errors are Python exceptions with
// the command line's messages: plate.InputError (a ValueError) for a bad scene, ValueError for a bad option, RuntimeError else.
//
// The pieces, one file per topic, are declared in bindings.hpp and registered here in order.
#include "bindings.hpp"

using namespace plate;
using namespace plate::python;

PYBIND11_MODULE(_plate, m) {
    m.doc() = "Sliding manipulation on a vibrating 6-DoF plate (Vose, Umbanhowar & Lynch): the compiled core";
    m.attr("__version__") = PLATE_VERSION;
    // Bad scene files and dicts: the message names the source and the field, as the command line's.
    static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            input_error(e.what());
        } catch (const Interrupted& e) {   // (asked to stop from C++: interrupt.hpp raises Python's own)
            PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
        }
    });

    bind_progress(m);
    bind_scene(m);
    bind_twist(m);
    bind_field(m);
    bind_fixed_points(m);
    bind_design(m);
    bind_simulate(m);
    bind_robustness(m);
    bind_observe(m);
    bind_identify(m);
    bind_control(m);
    bind_commands(m);
}
