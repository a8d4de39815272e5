// The envelope across the chi-square's cells (cells.cpp's envelope_sds, judge.cpp's add_envelope;
// IdentifyOptions::envelope): under static friction the fit's Jacobian is the tangent of one cell's floor,
// and the sds it gives measure the cell; secants over 3, 10 and 30 times the fine steps see the chi-square's
// envelope across several cells, and the within-cell sd is replaced by theirs where that is wider, the cells'
// spread kept beside it (docs/decisions/identification.md, "The envelope across the cells", with the figures).
#include "identify_fixtures.hpp"
#include "internal.hpp"
#include "plate/profile.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

using namespace plate;
using namespace plate::test;
using identify_detail::Layout;
using identify_detail::TrackCost;

namespace {

// The track costs of `tracks` under `nominal` (central differences) and the fit's starts [mm, mm, rad].
struct Costs {
    std::vector<std::unique_ptr<TrackCost>> owned;
    std::vector<TrackCost*> ptrs;
    std::vector<std::vector<double>> starts;
    Costs(const Scene& nominal, const Layout& layout, const std::vector<Track>& tracks, const IdentifyOptions& o,
          const IdentifySummary* fit) {
        for (std::size_t t = 0; t < tracks.size(); ++t) {
            owned.push_back(std::make_unique<TrackCost>(nominal, layout, tracks[t], 0, o, true));
            ptrs.push_back(owned.back().get());
            const Vec3 q = fit ? fit->tracks[t].start : tracks[t].q.front();
            starts.push_back({q.x() * 1e3, q.y() * 1e3, q.z()});
            starts.back().resize(nominal.part.point ? 2 : 3);
        }
    }
};

}   // namespace

// Closed form: parameters a (sd 2, of which cells 1: within-cell sqrt 3), b (sd 3), c (not identifiable) and
// d (sd 2, of which cells 1.5: within-cell sqrt 1.75); envelope sds 3, 2, 5 and 1.8. sd^2 = max(within,
// envelope)^2 + cells^2: a's 9 + 1 = 10, d's 3.24 + 2.25 = 5.49 (wider than its 2 though the envelope is
// narrower than the sd: it replaces the within-cell part only); b (envelope within its within-cell sd) and c
// (no sd) stay. A widened parameter's covariance row and column scale by its ratio (the diagonal by the
// square, correlations kept), its interval is set anew, sd_envelope^2 = envelope^2 - within^2 (a's 6, d's
// 1.49) with sd_cells kept, so the within-cell sd stays. Seen failing with the envelope as a floor on the
// whole sd (a's 3, d's 2) and with the diagonal scaled once (a's sqrt 10 x 2 against 10).
TEST_CASE("the envelope replaces a wider within-cell sd, the cells' spread kept beside it", "[identify][envelope]") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    IdentifySummary s;
    const auto param = [](double estimate, double sd, double sd_cells, bool identifiable) {
        FittedParameter p;
        p.estimate = estimate;
        p.sd = sd;
        p.sd_cells = sd_cells;
        p.identifiable = identifiable;
        p.lo = estimate - kZ95 * sd;
        p.hi = estimate + kZ95 * sd;
        return p;
    };
    s.params = {param(0.3, 2, 1, true), param(0.4, 3, 0, true), param(0.5, nan, nan, false), param(0.6, 2, 1.5, true)};
    s.covariance.resize(4, 4);
    s.covariance << 4, 1, nan, 0.5, 1, 9, nan, 0, nan, nan, nan, nan, 0.5, 0, nan, 4;
    identify_detail::add_envelope({3, 2, 5, 1.8}, s);
    const double wa = std::sqrt(10.0) / 2, wd = std::sqrt(5.49) / 2;
    CHECK(s.covariance(0, 0) == Approx(10).epsilon(1e-14));
    CHECK(s.covariance(3, 3) == Approx(5.49).epsilon(1e-14));
    CHECK(s.covariance(0, 1) == Approx(wa).epsilon(1e-14));
    CHECK(s.covariance(1, 0) == Approx(wa).epsilon(1e-14));
    CHECK(s.covariance(0, 3) == Approx(0.5 * wa * wd).epsilon(1e-14));
    CHECK(s.covariance(3, 0) == Approx(0.5 * wa * wd).epsilon(1e-14));
    CHECK(s.covariance(1, 1) == 9);
    CHECK(s.covariance(1, 3) == 0);
    CHECK(std::isnan(s.covariance(2, 2)));
    CHECK(s.params[0].sd == Approx(std::sqrt(10.0)).epsilon(1e-14));
    CHECK(s.params[0].sd_cells == 1);
    CHECK(s.params[0].sd_envelope == Approx(std::sqrt(6.0)).epsilon(1e-14));
    CHECK(within_cell_sd(s.params[0]) == Approx(std::sqrt(3.0)).epsilon(1e-14));
    CHECK(s.params[0].lo == Approx(0.3 - kZ95 * std::sqrt(10.0)).epsilon(1e-14));
    CHECK(s.params[0].hi == Approx(0.3 + kZ95 * std::sqrt(10.0)).epsilon(1e-14));
    CHECK(s.params[3].sd == Approx(std::sqrt(5.49)).epsilon(1e-14));
    CHECK(s.params[3].sd_cells == 1.5);
    CHECK(s.params[3].sd_envelope == Approx(std::sqrt(1.49)).epsilon(1e-14));
    CHECK(within_cell_sd(s.params[3]) == Approx(std::sqrt(1.75)).epsilon(1e-14));
    CHECK(s.params[1].sd == 3);
    CHECK(s.params[1].sd_cells == 0);
    CHECK(s.params[1].sd_envelope == 0);
    CHECK(s.params[1].lo == 0.4 - kZ95 * 3);
    CHECK(std::isnan(s.params[2].sd));
}

// fig1_point's part sliding throughout (no arrest, no cells; the cells test's case): its chi-square is
// smooth, so the secants over 3, 10 and 30 times the fine steps are its tangent to their second order -- the
// envelope's sd equals the fit's within 1 % (measured: see the INFO), and the reported sd is widened by no more.
// Seen failing with the tracks' starts' columns left out of the envelope's Jacobian (the starts not
// eliminated: the sd too narrow, 0.51 of the fit's).
TEST_CASE("a part that slides throughout: the envelope equals the fit's own sd", "[identify][envelope]") {
    const Scene nominal = scene("fig1_point");
    const std::vector<Track> tracks = {filmed(nominal, {"mu_k"}, {0.27}, strobe(0.1, 0, 3), Vec3(0.01, -0.02, 0), 5.0),
                                       filmed(nominal, {"mu_k"}, {0.27}, strobe(0.1, 0, 5), Vec3(-0.02, 0.01, 0), 5.0)};
    IdentifyOptions o = options({"mu_k"});
    o.threads = 2;
    o.cell_samples = 0;
    o.envelope = false;
    const IdentifySummary off = identify(nominal, tracks, o);
    o.envelope = true;
    const IdentifySummary on = identify(nominal, tracks, o);
    const Layout layout(nominal, {"mu_k"});
    Costs c(nominal, layout, tracks, o, &off);
    long simulations = 0;
    const std::vector<double> x = layout.internal({off.params[0].estimate});
    const std::vector<double> lo = {layout.lower(0, o)}, hi = {layout.upper(0, o)};
    const std::vector<double> env = identify_detail::envelope_sds(layout, o, c.ptrs, x, c.starts, {}, lo, hi, simulations);
    INFO("sd " << off.params[0].sd << ", envelope " << env[0] << ", reported with it " << on.params[0].sd);
    CHECK(std::abs(env[0] / off.params[0].sd - 1) < 0.01);
    // Per factor (3): the coefficient both ways on each of the 2 tracks, each track's 2 start coordinates both ways.
    CHECK(simulations == 3 * (2 * 2 + 2 * 2 * 2));
    CHECK(on.params[0].sd >= off.params[0].sd);
    CHECK(on.params[0].sd < 1.01 * off.params[0].sd);
    // The fit's own envelope is the test's (its starts round-tripped through metres): the sd it reports.
    CHECK(on.params[0].sd == Approx(std::max(env[0], off.params[0].sd)).epsilon(1e-6));
    CHECK(on.params[0].sd_cells == 0);
    CHECK(within_cell_sd(on.params[0]) == Approx(off.params[0].sd).epsilon(1e-9));
    CHECK(on.envelope_seconds > 0);
    CHECK(off.envelope_seconds == 0);
}
