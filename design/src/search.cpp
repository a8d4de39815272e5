// What every search shares: the flight check, the coefficient layout, the amplitude constraints.
#include "internal.hpp"

namespace plate {

using namespace design_detail;

// --- the flight check ----------------------------------------------------------------------------

// (design.hpp) 256 samples over the period.
double vertical_margin(const PlateMotion& u, double g, double half_width) {
    double worst = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 256; ++k) {
        Vec3 pdd, wd;
        u.acceleration(u.T * k / 256, pdd, wd);
        for (double x : {-half_width, half_width})
            for (double y : {-half_width, half_width}) worst = std::min(worst, (g + pdd.z() + wd.x() * y - wd.y() * x) / g);
    }
    return worst;
}

double flight_region(const Scene& part, const DesignOptions& opt) {
    double reach = 0;
    for (int i = 0; i < part.part.contacts(); ++i) reach = std::max(reach, part.part.c[i].head<2>().norm());
    return opt.region + (part.part.point ? 0.0 : reach);
}

PlateMotion motion_from(const std::vector<double>& p, const std::vector<Axis>& axes, const std::vector<int>& harmonics,
                        double T) {
    PlateMotion u;
    u.T = T;
    const int H = static_cast<int>(harmonics.size());
    for (int a = 0; a < static_cast<int>(axes.size()); ++a)
        for (int h = 0; h < H; ++h) {
            const double c = p[2 * (a * H + h)], s = p[2 * (a * H + h) + 1], amp = std::hypot(c, s);
            if (amp > 0) u.harmonics.push_back({axes[a], harmonics[h], amp, std::atan2(c, s)});
        }
    return u;
}


}   // namespace plate

namespace plate::design_detail {

// Harmonics combined per (axis, n) as phasors amp e^{i phase}: the amplitude a scene's reader sees.
std::map<std::pair<int, int>, std::complex<double>> phasors(const PlateMotion& u) {
    std::map<std::pair<int, int>, std::complex<double>> p;
    for (const Harmonic& h : u.harmonics) p[{static_cast<int>(h.axis), h.n}] += std::polar(h.amp, h.phase);
    return p;
}

// The motion with one harmonic per (axis, n) (amplitude >= 0), as a scene file states it.
PlateMotion combined(const PlateMotion& u) {
    PlateMotion r;
    r.T = u.T;
    for (const auto& [k, z] : phasors(u))
        if (std::abs(z) > 0) r.harmonics.push_back({static_cast<Axis>(k.first), k.second, std::abs(z), std::arg(z)});
    return r;
}

// --- what the searches share -----------------------------------------------------------------------

// The coefficients of u in motion_from's layout; empty if u has a harmonic outside it.
std::vector<double> params_from(const PlateMotion& u, const std::vector<Axis>& axes, const std::vector<int>& harmonics) {
    const int H = static_cast<int>(harmonics.size());
    std::vector<double> p(2 * axes.size() * H, 0.0);
    for (const auto& [k, z] : phasors(u)) {
        const auto a = std::find(axes.begin(), axes.end(), static_cast<Axis>(k.first)) - axes.begin();
        const auto h = std::find(harmonics.begin(), harmonics.end(), k.second) - harmonics.begin();
        if (a == static_cast<long>(axes.size()) || h == H) return {};
        p[2 * (a * H + h)] = z.imag();       // amp sin(phase): the cosine's coefficient
        p[2 * (a * H + h) + 1] = z.real();   // amp cos(phase): the sine's
    }
    return p;
}

// Eight points on the edge of the region |s_x|, |s_y| <= R: corners and midpoints.
std::array<Vec2, 8> region_edge(double R) {
    return {Vec2(-R, -R), Vec2(0, -R), Vec2(R, -R), Vec2(R, 0), Vec2(R, R), Vec2(0, R), Vec2(-R, R), Vec2(-R, 0)};
}

// A limit cycle's twist error relative to v_ref (and v_ref / rho): its tolerance plus the integrator's,
// ~60 rtol v_ref (field.hpp).
double cycle_noise(const LimitCycleOptions& o) { return o.tol + 60 * o.integration.rtol; }

// The option's task runner, else its threads.
TaskRunner runner(const DesignOptions& opt) { return opt.tasks ? opt.tasks : thread_tasks(opt.threads); }

// c_a <= 0 for each axis' peak of `fin` (axis_peaks) within `room` times the axis' limit (6 entries),
// then c <= 0 for no flight over the region, then the corner limits' (corner_count(opt)); returns the
// entries written.
int peak_constraints(const PlateMotion& fin, const DesignOptions& opt, const Scene& part, double room, double* c) {
    const Vec6 peak = axis_peaks(fin);
    for (int axis = 0; axis < 6; ++axis) {
        const double lim = axis < 3 ? opt.lin_limit : opt.ang_limit;
        c[axis] = (peak[axis] - room * lim) / std::max(lim, 1e-12);
    }
    c[6] = opt.flight_margin - vertical_margin(fin, part.g, flight_region(part, opt));
    return kPeakConstraints + corner_constraints(fin, opt, part, room, c + kPeakConstraints);
}

int corner_count(const DesignOptions& opt) {
    return opt.corner_displacement_limit > 0 || opt.corner_velocity_limit > 0 ? kCornerConstraints : 0;
}

int corner_constraints(const PlateMotion& fin, const DesignOptions& opt, const Scene& part, double room, double* c) {
    if (corner_count(opt) == 0) return 0;
    const CornerPeaks p = corner_peaks(fin, corner_half_size(part, opt));
    const auto bound = [&](double peak, double lim) { return lim > 0 ? (peak - room * lim) / lim : -1.0; };
    c[0] = bound(p.displacement, opt.corner_displacement_limit);
    c[1] = bound(p.velocity, opt.corner_velocity_limit);
    return kCornerConstraints;
}

Vec2 corner_half_size(const Scene& part, const DesignOptions& opt) {
    if (opt.plate_half_size.x() > 0) return opt.plate_half_size;
    const double h = flight_region(part, opt);
    return Vec2(h, h);
}


}   // namespace plate::design_detail
