// Pickled state of the larger results (plate.FixedPoints, Design, Robustness, Identification,
// ControlRun) and of what they hold: each struct's members are listed once, in one `io(Archive&, T&)`
// overload below, and one archive both writes them to bytes and reads them back -- numbers as their
// bytes (doubles to the bit, NaN kept), a scene as its file text (as plate.Scene pickles), a JSON
// value as CBOR. The state opens with the result's kind and the module's version: a state of another
// kind or version, or one that ends early or runs on, is refused (ValueError), never half read.
// (The smaller results -- Field, Trajectory, Cycle, Track -- pickle as tuples, conversions.cpp.)
#pragma once

#include "bindings.hpp"

#include "plate/robustness.hpp"
#include "plate/uncertainty.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <complex>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace plate::python::pickling {

class Archive {
public:
    Archive() = default;                                                              // to write
    explicit Archive(std::string bytes) : reading_(true), buf_(std::move(bytes)) {}   // to read
    bool reading() const { return reading_; }
    // n bytes to or from p.
    void raw(void* p, std::size_t n);
    // The members, in order.
    template <class... T>
    void operator()(T&... v) {
        (io(*this, v), ...);
    }
    std::size_t left() const { return buf_.size() - pos_; }
    const std::string& bytes() const { return buf_; }

private:
    bool reading_ = false;
    std::string buf_;
    std::size_t pos_ = 0;
};

// --- numbers, text, containers ---------------------------------------------------------------------

template <class T, std::enable_if_t<std::is_arithmetic_v<T> || std::is_enum_v<T>, int> = 0>
void io(Archive& a, T& v) {
    a.raw(&v, sizeof v);
}
template <class T>
void io(Archive& a, std::complex<T>& v) {
    a.raw(&v, sizeof v);
}
// A count, checked against what is left to read (each element takes at least `least` bytes).
std::size_t count(Archive& a, std::size_t n, std::size_t least);
void io(Archive& a, std::string& s);
// An interned unit string (UncertainParameter::unit points at a constant).
void io(Archive& a, const char*& s);
template <class T>
void io(Archive& a, std::vector<T>& v) {
    std::size_t n = count(a, v.size(), 1);
    if (a.reading()) {
        v.clear();
        v.resize(n);
    }
    for (T& x : v) io(a, x);
}
void io(Archive& a, std::vector<bool>& v);
template <class T, std::size_t N>
void io(Archive& a, std::array<T, N>& v) {
    for (T& x : v) io(a, x);
}
template <class A, class B>
void io(Archive& a, std::pair<A, B>& p) {
    a(p.first, p.second);
}
template <class T>
void io(Archive& a, std::optional<T>& o) {
    bool has = o.has_value();
    io(a, has);
    if (a.reading() && has) o.emplace();
    if (a.reading() && !has) o.reset();
    if (has) io(a, *o);
}
template <class S, int R, int C, int O, int MR, int MC>
void io(Archive& a, Eigen::Matrix<S, R, C, O, MR, MC>& m) {
    std::int64_t rows = m.rows(), cols = m.cols();
    if constexpr (R == Eigen::Dynamic || C == Eigen::Dynamic) {
        a(rows, cols);
        const std::size_t n = count(a, static_cast<std::size_t>(rows * cols), sizeof(S));
        if (a.reading()) m.resize(rows, cols);
        a.raw(m.data(), n * sizeof(S));
    } else {
        a.raw(m.data(), sizeof(S) * R * C);
    }
}
void io(Archive& a, nlohmann::json& j);
void io(Archive& a, Scene& s);

// --- the library's structs (pickling.cpp) ----------------------------------------------------------

void io(Archive& a, StopEvent& e);
void io(Archive& a, GridSpec& g);
void io(Archive& a, IntegrationOptions& o);
void io(Archive& a, LimitCycleOptions& o);
void io(Archive& a, FixedPointOptions& o);   // (not its stop request: none after a load)
void io(Archive& a, FixedPoint& p);
void io(Archive& a, FixedLine& l);
void io(Archive& a, StuckRegion& r);
void io(Archive& a, RotatingAttractor& r);
void io(Archive& a, FixedPoints& f);
void io(Archive& a, DesignStartRun& r);
void io(Archive& a, DesignSummary::Competitor& c);
void io(Archive& a, DesignSummary::OrientationPull& p);
void io(Archive& a, DesignSummary& d);
void io(Archive& a, Spread& s);
void io(Archive& a, UncertaintySpec& u);
void io(Archive& a, UncertainParameter& p);
void io(Archive& a, Sensitivity& s);
void io(Archive& a, DrawResult& d);
void io(Archive& a, RobustnessSummary& s);
void io(Archive& a, RobustnessOptions& o);   // (not its task runner: the default after a load)

// --- a result as bytes, and back ---------------------------------------------------------------------

// The heading: the kind (e.g. "plate.Design") and the module's version.
void heading(Archive& a, const char* kind);
// Nothing left after the last member, else ValueError.
void finished(const Archive& a, const char* kind);

template <class T>
py::bytes pickled(const T& x, const char* kind) {
    Archive a;
    heading(a, kind);
    io(a, const_cast<T&>(x));   // (writing only reads x)
    return py::bytes(a.bytes());
}
template <class T>
T unpickled(const py::bytes& state, const char* kind) {
    Archive a{std::string(state)};
    heading(a, kind);
    T x{};
    io(a, x);
    finished(a, kind);
    return x;
}
// A class's py::pickle: .def(pickle_as<T>("plate.Kind")).
template <class T>
auto pickle_as(const char* kind) {
    return py::pickle([kind](const T& x) { return pickled(x, kind); },
                      [kind](const py::bytes& state) { return unpickled<T>(state, kind); });
}

}   // namespace plate::python::pickling
