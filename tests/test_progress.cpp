// Long calls stop when asked (plate/progress.hpp): a field and a fixed-point search throw Interrupted,
// on every worker, within a step of the integrator; and the progress clock's estimate of the time left.
#include "plate/field.hpp"
#include "plate/progress.hpp"
#include "plate/simulate.hpp"
#include "shipped_scenes.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <functional>
#include <thread>

using namespace plate;
using plate_tests::scene;

namespace {

// Seconds from stop.request(), made from another thread `after_ms` into call() under a StopScope of
// it, to the Interrupted that call() throws (-1: it returned).
double latency_of_request(StopRequest& stop, int after_ms, const std::function<void()>& call) {
    std::chrono::steady_clock::time_point asked;
    std::thread asker([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(after_ms));
        asked = std::chrono::steady_clock::now();
        stop.request();
    });
    double latency = -1;
    try {
        const StopScope scope(&stop);
        call();
    } catch (const Interrupted&) {
        latency = std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
    }
    asker.join();
    return latency;
}

}   // namespace

TEST_CASE("A stop request stops a field on every worker within 0.5 s and throws Interrupted", "[field][interrupt]") {
    // fig6 at grid 25 takes about 12 s on two cores. The request (given in the options) is set 0.3 s
    // in; the field's two workers see it at their next integrator step: measured 1-5 ms from the
    // request to the exception here (without the engine's poll, between configurations: 5 ms too, fig6's
    // cycles being short; the simulation below is where that poll is needed).
    const Scene sc = scene("fig6");
    GridSpec g;
    g.nx = g.ny = g.nth = 25;
    StopRequest stop;
    FieldOptions o;
    o.threads = 2;
    o.stop = &stop;
    const double latency = latency_of_request(stop, 300, [&] { compute_field(sc, g, o); });
    INFO("latency " << latency << " s");
    CHECK(latency >= 0);
    CHECK(latency < 0.5);
}

TEST_CASE("A stop request stops a long simulation within 0.5 s: the integrator polls it at every step", "[interrupt]") {
    // fig4's full dynamics over 2000 s (1e5 periods, about 7 s here): one call, no unit of work but the step.
    // Measured 5 ms from the request to the exception; with the engine's poll removed the simulation
    // ran to its end, 6.6 s after the request.
    const Scene sc = scene("fig4");
    StopRequest stop;
    const double latency =
        latency_of_request(stop, 200, [&] { simulate(sc, Dynamics::Full, Vec3(0.01, 0, 0), Vec3::Zero(), 2000.0, 1.0); });
    INFO("latency " << latency << " s");
    CHECK(latency >= 0);
    CHECK(latency < 0.5);
}

TEST_CASE("A request set from the progress callback stops the field after the configurations done", "[field][interrupt]") {
    const Scene sc = scene("fig4");
    StopRequest stop;
    FieldOptions o;
    o.threads = 2;
    int reported = 0;
    o.progress = [&](int done, int) {
        reported = done;
        if (done >= 5) stop.request();
    };
    o.stop = &stop;
    CHECK_THROWS_AS(compute_field(sc, GridSpec{}, o), Interrupted);
    CHECK(reported >= 5);
    CHECK(reported < GridSpec{}.size());
}

TEST_CASE("A stop request stops a fixed-point search and throws Interrupted", "[field][interrupt]") {
    const Scene sc = scene("fig4");
    GridSpec g;
    g.nx = g.ny = g.nth = 5;
    const Field f = compute_field(sc, g);
    FixedPointOptions o;
    REQUIRE(find_fixed_points(sc, f, o).candidates > 0);   // (else no cycle would run to see the request)
    StopRequest stop;
    stop.request();
    o.stop = &stop;
    CHECK_THROWS_AS(find_fixed_points(sc, f, o), Interrupted);
    // Installed for a scope, a request reaches calls that take none in their options.
    const StopScope scope(&stop);
    CHECK_THROWS_AS(find_fixed_points(sc, f), Interrupted);
}

TEST_CASE("The time left is the mean time per unit so far times the units left", "[interrupt]") {
    const ProgressClock clock;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const Progress none = clock.at(0, 10), some = clock.at(4, 10), all = clock.at(10, 10);
    CHECK(std::isnan(none.seconds_left));
    CHECK(some.seconds >= 0.02);
    CHECK(some.seconds_left == Approx(some.seconds / 4 * 6).epsilon(1e-12));
    CHECK(all.seconds_left == 0);
}
