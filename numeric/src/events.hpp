// Internal: event location -- the first root of a guard within an accepted step, found on the
// step's dense output (no re-stepping; one evaluation per iterate). Knows nothing of contacts or
// modes (engine.hpp says which guards there are and what crossing one means).
#pragma once

namespace plate::detail {

// First root in (a, b] of a guard whose values at the step's ends are ga (not crossed) and gb
// (crossed), by the Illinois variant of regula falsi with a bisection every eighth iterate, until
// b - a <= tol (at most 200 iterates). guard_at(m) evaluates the guard at time m;
// crossed(g_a, g_m) says whether the guard has crossed between a value g_a and g_m; keep() is
// called when an iterate becomes the new right end (the caller keeps its state there, where the
// guard is already crossed). Returns that right end.
template <class GuardAt, class Crossed, class Keep>
double illinois_first_root(double a, double b, double ga, double gb, double tol, GuardAt&& guard_at, Crossed&& crossed,
                           Keep&& keep) {
    int side = 0;
    for (int it = 0; it < 200 && b - a > tol; ++it) {
        double m = gb != ga ? (a * gb - b * ga) / (gb - ga) : 0.5 * (a + b);
        if (!(m > a && m < b) || it % 8 == 7) m = 0.5 * (a + b);
        const double gm = guard_at(m);
        if (crossed(ga, gm)) {
            b = m;
            gb = gm;
            keep();
            if (side == -1) ga *= 0.5;   // Illinois: the end that stays is weighted down
            side = -1;
        } else {
            a = m;
            ga = gm;
            if (side == 1) gb *= 0.5;
            side = 1;
        }
    }
    return b;
}

}   // namespace plate::detail
