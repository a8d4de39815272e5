#include "report.hpp"
#include "report_html.hpp"

#include "plate/design.hpp"
#include "plate/field.hpp"
#include "plate/output.hpp"
#include "plate/scene_io.hpp"
#include "plate/study.hpp"
#include "derivation.hpp"
#include "theorem1.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

namespace plate::report {
namespace fs = std::filesystem;

namespace {

using namespace html;

void section_derivation(Ctx& c) {
    const symbolic::Derivation d = symbolic::derive();   // run here: every line below is this run's
    c.html << "<h2>1. Symbolic derivation</h2>\n<p>Derived with GiNaC from frames, contact kinematics, Coulomb "
              "forces and Newton–Euler (<code>symbolic/derivation.cpp</code>), time derivatives by a jet rule; each printed "
              "equation compared with the derived one:</p>\n<table><tr><th>equation</th><th>verdict</th><th>printed</th>"
              "<th>derived</th><th>why</th></tr>\n";
    int differ = 0;
    for (const auto& f : d.findings) {
        differ += !f.agrees;
        c.html << "<tr><td>" << esc(f.equation) << "</td><td>"
               << (f.agrees ? "<span class=\"pass\">agrees</span>" : "<span class=\"fail\">differs</span>") << "</td><td><code>"
               << esc(f.printed) << "</code></td><td><code>" << esc(f.derived) << "</code></td><td>" << esc(f.reason) << "</td></tr>\n";
    }
    c.html << "</table>\n<p>" << d.findings.size() << " comparisons, " << differ << " differ.</p>\n<h3>Derived equations</h3>\n";
    std::istringstream in(symbolic::latex_report(d));
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("\\paragraph{", 0) != 0) continue;
        const auto close = line.find("}");
        const std::string title = line.substr(11, close - 11);
        const auto a = line.find('$', close), b = line.rfind('$');
        c.html << "<h4>" << esc(title) << "</h4><div class=\"math\">$$" << esc(line.substr(a + 1, b - a - 1))
               << "$$</div>\n";
    }
}

void section_kernels(Ctx& c, std::uint64_t seed) {
    double worst = 0;
    int n = 0;
    for (std::uint64_t s = 0; s < 60; ++s) {
        RandomSceneOptions ro;
        ro.thin = s % 3 == 1;
        ro.point = s % 3 == 2;
        const Scene sc = random_scene(seed + 1000 + s, ro);
        Rng r(seed + s);
        Workspace g, f;
        for (int k = 0; k < 100; ++k, ++n) {
            const Vec3 q{r.uniform(-0.03, 0.03), r.uniform(-0.03, 0.03), r.uniform(-kPi, kPi)};
            const Vec3 qd{r.uniform(-0.3, 0.3), r.uniform(-0.3, 0.3), r.uniform(-20, 20)};
            const PlateState ps = plate_state(sc.plate, r.uniform(0, sc.plate.T), Dynamics::U);
            accelerations(sc, Dynamics::U, q, qd, ps, g);
            accelerations_reference(sc, Dynamics::U, q, qd, ps, f);
            const double mg = sc.part.m * sc.g;
            worst = std::max({worst, (g.qdd - f.qdd).head<2>().norm() / sc.g, std::abs(g.qdd[2] - f.qdd[2]) * sc.part.rho() / sc.g,
                              (g.n - f.n).norm() / mg});
        }
    }
    c.html << "<h2>2. Generated kernels against the hand-written reference</h2>\n<table><tr><th>states</th><th>parts</th>"
              "<th>worst difference (relative to g, m g)</th><th>bound</th><th>verdict</th></tr><tr><td>"
           << n << "</td><td>thick, thin, point</td><td>" << fmt(worst, 3) << "</td><td>1e-12</td><td>"
           << verdict(worst < 1e-12) << "</td></tr></table>\n";
}

void section_proofs(Ctx& c, const ReportOptions& opt) {
    const int n_thin = opt.quick ? 24 : 10000, n_thick = opt.quick ? 8 : 1000, n_surf = opt.quick ? 4 : 200;
    proofs::ContractionSummary thin, thick;
    auto run = [&](bool is_thin, int n, std::uint64_t s0) {
        proofs::ContractionOptions o;
        o.cases = n;
        o.seed = s0;
        o.thin = is_thin;
        o.threads = opt.threads;
        o.progress = ProgressPrinter{is_thin ? "report, thin parts" : "report, thick parts", 10.0};
        return proofs::check_contraction(o);
    };
    c.timed("Theorem 1 contraction, thin parts", [&] { thin = run(true, n_thin, opt.seed); });
    c.timed("contraction beyond the theorem, thick parts", [&] { thick = run(false, n_thick, opt.seed + 50'000'000); });
    c.html << "<h2>3. Theorem 1: contraction of the relative twist (Appendix C)</h2>\n"
              "<p>Two copies of a random part at a random configuration, from random twists, integrated on one step "
              "sequence; V = ½|ξ<sub>rel</sub>|² in scaled coordinates (ξ<sub>θ</sub> = ρω). A rise of V between steps "
              "is compared with the bound on its integration error, |ξ<sub>rel</sub>|·2√3δ + 6δ², δ = rtol (v<sub>ref</sub> "
              "+ |ξ|) (the controller's acceptance test on the scaled state). Floquet multipliers: eigenvalues of the "
              "period map's Jacobian at the cycle (central differences). Uniqueness: four more initial twists reach the "
              "same cycle start within 10<sup>-6</sup> v<sub>ref</sub>.</p>\n<table><tr><th>parts</th><th>cases</th><th>in model"
              "</th><th>V never rises beyond error</th><th>worst rise / bound</th><th>V → 0</th><th>median contraction / period"
              "</th><th>max Floquet |λ|</th><th>unique cycle</th><th>counter-examples (seeds)</th><th>verdict</th></tr>\n";
    bool theorem = true;
    auto row = [&](const char* name, const proofs::ContractionSummary& s) {
        std::string ce;
        for (std::size_t i = 0; i < s.counterexamples.size() && i < 8; ++i) ce += (i ? ", " : "") + std::to_string(s.counterexamples[i]);
        if (s.counterexamples.size() > 8) ce += ", …";
        const bool observation1 = s.valid > 0 && s.converged == s.valid && s.unique == s.valid && s.floquet_below_one == s.valid;
        c.html << "<tr><td>" << name << "</td><td>" << s.cases << "</td><td>" << s.valid << "</td><td>" << s.monotone
               << "</td><td>" << (s.worst_increase > 0 ? fmt(s.worst_increase, 3) + " (seed " + std::to_string(s.worst_seed) + ")" : "none")
               << "</td><td>" << s.converged << "</td><td>" << fmt(s.median_rate, 3) << "</td><td>" << fmt(s.max_spectral_radius, 3)
               << "</td><td>" << s.unique << "</td><td>" << (ce.empty() ? "none" : ce) << "</td><td>";
        if (theorem) c.html << "Theorem 1: " << verdict(s.passed());
        else c.html << "V monotone: " << (s.monotone == s.valid ? verdict(true) : "<span class=\"fail\">no, " + std::to_string(s.valid - s.monotone) + " cases</span>")
                    << "; Observation 1: " << verdict(observation1);
        c.html << "</td></tr>\n";
    };
    theorem = true;
    row("thin (Theorem 1)", thin);
    theorem = false;
    row("thick (beyond it)", thick);
    c.html << "</table>\n<p>These checks hold for any Coulomb friction with velocity-independent normal forces: they are "
              "tied to the dynamics at " << thin.tie.samples << " sampled states of the thin parts, where the normal forces must "
              "equal an independent solve of the part's statics and m q'' + b~ the limit-surface wrench (39) of the relative "
              "twist, both to " << fmt(proofs::kTieTolerance, 1) << " m g: worst " << fmt(thin.tie.worst_statics, 2) << " and "
           << fmt(thin.tie.worst_wrench, 2) << " m g, "
           << (thin.tie.passed() ? verdict(true) : "<span class=\"fail\">" + esc(thin.tie.failure) + "</span>")
           << " (a wrong normal force, a swapped lever arm and a wrong mu on one contact each fail it: test).</p>\n";
    c.html << "<p>Thick parts are outside Theorem 1: V may rise (the normal forces depend on the twist). "
           << esc(observation1_sentence(thick.valid, thick.converged, thick.unique, thick.floquet_below_one))
           << (thick.monotone < thick.valid
                   ? " The seeds above reproduce the " + std::to_string(thick.valid - thick.monotone) + " cases where V rose."
                   : std::string(" V never rose beyond its error bound in this campaign."))
           << "</p>\n";
    {   // V per period, log scale: a few thin cases and the worst thick one
        auto o = c.data("V.dat");
        int cols = 0;
        std::vector<const proofs::ContractionCase*> show;
        for (const auto& d : thin.details)
            if (d.valid && show.size() < 5) show.push_back(&d);
        for (const auto& d : thick.details)
            if (d.seed == thick.worst_seed && d.valid) show.push_back(&d);
        std::size_t len = 0;
        for (auto* d : show) len = std::max(len, d->V_periods.size());
        for (std::size_t k = 0; k < len; ++k) {
            o << k;
            for (auto* d : show) o << ' ' << (k < d->V_periods.size() ? d->V_periods[k] / d->V0 : NAN);
            o << '\n';
        }
        o.close();
        cols = static_cast<int>(show.size());
        std::string s = "set logscale y\nset format y '10^{%L}'\nset xlabel 'period'\nset ylabel 'V / V_0'\nset key top right\nplot ";
        for (int i = 0; i < cols; ++i)
            s += std::string(i ? ", " : "") + "'data/V.dat' u 1:" + std::to_string(i + 2) + " w lp pt 7 ps 0.4 t '" +
                 (i + 1 == cols && show.back()->seed == thick.worst_seed ? "thick, seed " : "thin, seed ") +
                 std::to_string(show[i]->seed) + "'";
        c.plot("lyapunov_V", s + "\n", "V(t) = ½|ξ<sub>rel</sub>|² at period boundaries, log scale: thin parts contract "
                                       "geometrically; the worst thick case shown last.");
    }
    // Appendix D: the cycle repeats with period T.
    {
        int n = 0, ok = 0;
        double worst1 = 0, worst2 = 0;
        for (std::uint64_t k = 0; k < 20; ++k) {
            const Scene sc = random_scene(opt.seed + 70'000'000 + k, RandomSceneOptions{k % 2 == 0});
            LimitCycleOptions lo;
            lo.integration.rtol = 1e-11;
            lo.tol = 1e-10;
            const Vec3 q(0.01, -0.005, 0.7);
            const LimitCycleSummary lc = limit_cycle(sc, q, lo, Vec3(0.05, 0, 1));
            if (!lc.converged) continue;
            IntegrationOptions io;
            io.rtol = 1e-11;
            Vec3 p1, p2;
            if (!period_map(sc, q, lc.qd_start, p1, io) || !period_map(sc, q, p1, p2, io)) continue;
            const double v = sc.v_ref();
            const double e1 = (p1 - lc.qd_start).head<2>().norm() / v, e2 = (p2 - lc.qd_start).head<2>().norm() / v;
            worst1 = std::max(worst1, e1);
            worst2 = std::max(worst2, e2);
            ++n;
            ok += e1 < 1e-8 && e2 < 1e-8;
        }
        c.html << "<h3>Periodicity (Appendix D)</h3>\n<table><tr><th>converged cycles (thin and thick)</th><th>worst "
                  "|P(x*) − x*| / v<sub>ref</sub></th><th>worst |P²(x*) − x*| / v<sub>ref</sub></th><th>tolerance</th>"
                  "<th>verdict</th></tr><tr><td>" << n << "</td><td>" << fmt(worst1, 3) << "</td><td>" << fmt(worst2, 3)
               << "</td><td>1e-8</td><td>" << verdict(n > 0 && ok == n) << "</td></tr></table>\n";
    }
    // Limit surfaces
    proofs::LimitSurfaceCampaign ls;
    c.timed("limit surfaces", [&] { ls = proofs::check_limit_surfaces(n_surf, opt.seed); });
    c.html << "<h2>4. Limit surfaces (Appendix B)</h2>\n<p>Wrenches of random thin parts sampled on 300 twist directions; "
              "all pairs tested. Maximum work: ξ<sub>i</sub>·w<sub>j</sub> ≥ ξ<sub>i</sub>·w<sub>i</sub> (convex surface, twist "
              "normal to it); (40): (ξ<sub>i</sub>−ξ<sub>j</sub>)·(w<sub>i</sub>−w<sub>j</sub>) ≤ 0; no vertices: distinct "
              "directions give distinct wrenches; no flat faces: the max-work inequality is strict between distinct directions.</p>\n"
              "<table><tr><th>parts</th><th>convex and normal</th><th>strictly convex</th><th>worst max-work "
              "violation</th><th>worst (40) violation</th><th>smallest strict margin</th><th>smallest wrench separation</th><th>verdict</th></tr><tr><td>"
           << ls.parts << "</td><td>" << ls.convex << "</td><td>" << ls.strict << "</td><td>" << fmt(ls.worst_max_work, 3) << "</td><td>"
           << fmt(ls.worst_monotonicity, 3) << "</td><td>" << fmt(ls.min_strict_margin, 3) << "</td><td>" << fmt(ls.min_separation, 3)
           << "</td><td>" << verdict(ls.passed()) << "</td></tr></table>\n<p>The first two inequalities hold for any wrench of "
              "the form −Σ c<sub>i</sub> G<sub>i</sub> v<sub>i</sub>/|v<sub>i</sub>| with c<sub>i</sub> ≥ 0 (Cauchy-Schwarz), so a kernel "
              "fed a wrong μ or lever arm passes them. What can fail: each part's friction set built independently (every "
              "force of magnitude ≤ μ<sub>i</sub>N<sub>i</sub> at each contact, N from the part's statics, each disk's rim "
              "sampled at 720 points): the kernel's wrench for ξ must be the set's support point in −ξ and inside the set. "
           << ls.on_set << " of " << ls.parts << " parts: worst support-point error " << fmt(ls.worst_support, 2)
           << ", worst excursion outside " << fmt(ls.worst_outside, 2) << " (of Σ μN; 1e-12 passes; a wrong μ or lever arm "
              "fails it: test).</p>\n<p>Each part's dynamics tied to its surface at "
           << ls.tie.samples << " states (statics and wrench, as above): worst " << fmt(ls.tie.worst_statics, 2) << " and "
           << fmt(ls.tie.worst_wrench, 2) << " m g"
           << (ls.tie.passed() ? "." : ": <span class=\"fail\">" + esc(ls.tie.failure) + "</span>") << "</p>\n";
    {
        const Scene sc = random_scene(opt.seed + 90'000'000, RandomSceneOptions{true});
        double scale = 0;
        const auto w = proofs::thin_wrench_map(sc, Vec3::Zero(), 0, &scale);
        auto o = c.data("surface.dat");
        const int n = 2500;
        const double golden = kPi * (3 - std::sqrt(5.0));
        for (int k = 0; k < n; ++k) {
            const double z = 1 - (2 * k + 1.0) / n, rad = std::sqrt(1 - z * z), a = golden * k;
            const Vec3 x = w(Vec3(rad * std::cos(a), rad * std::sin(a), z)) / scale;
            o << x[0] << ' ' << x[1] << ' ' << x[2] << '\n';
        }
        o.close();
        c.plot("limit_surface", "set xlabel 'F_x / Σ μN'\nset ylabel 'F_y / Σ μN'\nset zlabel 'τ/(ρ Σ μN)'\nset view 60,30\n"
                                "splot 'data/surface.dat' w p pt 7 ps 0.25 lc rgb '#3060a0' notitle\n",
               "Limit surface of a random thin part: the wrench −∇P(ξ) for 2500 twist directions.");
    }
    // Collinearity: conditioning of A
    c.html << "<h3>Invertibility of A and collinear contacts</h3>\n<p>The third contact approaches the line of the "
              "other two; two distinct twists (pure y-translation, and one with a spin that keeps every contact moving along "
              "+y) are compared by their wrenches.</p>\n"
              "<table><tr><th>contacts (−L,0), (L,0), (0,e), e/L</th><th>cond(A), dimensionless</th><th>wrench gap / Σ μN</th>"
              "<th>convex and normal</th></tr>\n";
    const double L = 0.03;
    std::vector<double> conds, gaps;   // for e > 0, in the order of the table
    double singular = 1;               // sigma_min / sigma_max at e = 0
    for (const auto& cs : proofs::collinear_scenes({1.0, 0.1, 0.01, 0.001, 0.0})) {
        const double e = cs.e_over_L;
        const Scene& sc = cs.scene;
        const auto cond = proofs::condition_of_A(sc, 20, opt.seed);
        std::string gap = "–", cv = "–";
        if (e > 0) {
            Scene s2 = sc;
            s2.part.mu.setConstant(0.3);
            s2.plate.harmonics.clear();
            double scale = 0;
            const auto w = proofs::thin_wrench_map(s2, Vec3::Zero(), 0, &scale);
            const double g = (w(Vec3(0, 1, 0)) - w(Vec3(0, 1, s2.part.rho() * 0.5 / L).normalized())).norm() / scale;
            gap = fmt(g, 3);
            gaps.push_back(g);
            conds.push_back(cond.max_condition);
            cv = proofs::check_limit_surface(w, scale, 200).convex_and_normal() ? "yes" : "no";
        } else {
            singular = cond.min_singular;
        }
        c.html << "<tr><td>" << e << "</td><td>" << (e > 0 ? fmt(cond.max_condition, 3) : "singular (σ_min/σ_max = " + fmt(cond.min_singular, 2) + ")")
               << "</td><td>" << gap << "</td><td>" << cv << "</td></tr>\n";
    }
    c.html << "</table>\n<p>" << esc(collinear_sentence(conds, gaps, singular)) << "</p>\n";
}

void section_fig3(Ctx& c, const fs::path& src) {
    const Scene sc = load_scene((src / "scenes/fig3_random.json").string());
    LimitCycleOptions lo;
    lo.record = true;
    lo.max_periods = 10;
    lo.tol = 0;   // ten periods, as Fig. 3
    const Vec3 q(0.01, -0.01, 0.5);
    const double v = sc.v_ref(), w = v / sc.part.rho();
    const LimitCycleSummary a = limit_cycle(sc, q, lo, Vec3(v, -0.5 * v, 0.5 * w));
    const LimitCycleSummary b = limit_cycle(sc, q, lo, Vec3(-0.8 * v, 0.8 * v, -w));
    for (const auto* p : {&a, &b}) {
        auto o = c.data(p == &a ? "fig3a.dat" : "fig3b.dat");
        for (const auto& s : p->path) o << s.qd[0] << ' ' << s.qd[1] << ' ' << s.qd[2] << ' ' << s.t << '\n';
        auto m = c.data(p == &a ? "fig3a_T.dat" : "fig3b_T.dat");
        for (const auto& s : p->path)
            if (std::abs(std::remainder(s.t, sc.plate.T)) < 1e-12) m << s.qd[0] << ' ' << s.qd[1] << ' ' << s.qd[2] << '\n';
    }
    c.html << "<h2>5. Observation 1 (Fig. 3)</h2>\n<p>Scene <code>fig3_random</code> at (0.01, −0.01, 0.5): two initial "
              "twists, ten periods of the reduced U-dynamics; open circles every T.</p>\n";
    c.plot("fig3", "set xlabel 'ṡ_x'\nset ylabel 'ṡ_y'\nset zlabel 'θ̇'\nset view 60,40\n"
                   "splot 'data/fig3a.dat' u 1:2:3 w l lc rgb '#c03030' t 'start 1', 'data/fig3b.dat' u 1:2:3 w l lc rgb '#3050c0' t 'start 2', "
                   "'data/fig3a_T.dat' w p pt 6 lc rgb '#c03030' notitle, 'data/fig3b_T.dat' w p pt 6 lc rgb '#3050c0' notitle\n",
           "Two initial twists converging to one limit cycle (twist space).");
}

// Stick-slip against the regularised-friction limit (study.hpp): a cycle that pivots and one with a
// short phase stuck as a whole, on fig6's thick part.
void section_stick_reference(Ctx& c, const fs::path& src, bool quick) {
    const Scene sc = load_scene((src / "scenes/fig6.json").string());
    const double v = sc.v_ref();
    const Vec3 S(v, v, v / sc.part.rho());
    c.html << "<h3>Stick-slip against the regularised-friction limit</h3>\n<p>The engine holds a contact (or the "
              "part) as long as <i>some</i> static friction inside the disks can (rigid Coulomb friction: the distribution "
              "is indeterminate). The reference replaces Coulomb's law by f = −μN v/√(|v|²+ε²) (no stick, no events; GSL "
              "bsimp), ε = 10<sup>-5</sup>…10<sup>-8</sup> v<sub>ref</sub>, extrapolated to ε = 0 with the observed order. "
              "Differences relative to v<sub>ref</sub>:</p>\n<table><tr><th>configuration (fig6)</th><th>cycle</th>"
              "<th>engine</th><th>regularised limit</th><th>observed order</th><th>difference</th><th>reference's error</th></tr>\n";
    Vec3 qs[] = {Vec3(0.0333333333333, 0.0166666666667, 1.7951958020513104), Vec3(0.0166666666667, 0, 2.6927937030769655)};
    int stuck_differ = 0, agree = 0;   // cycles stuck as a whole beyond the reference's error; cycles within it
    for (const Vec3& q : qs) {
        LimitCycleOptions o;
        o.integration.rtol = 1e-10;
        o.tol = 1e-9;
        const LimitCycleSummary lc = limit_cycle(sc, q, o);
        const RegularisedReference r = regularised_reference(sc, q);
        const bool stuck = lc.start_mode.kind == ModeKind::Stuck ||
                           std::any_of(lc.mode_events.begin(), lc.mode_events.end(),
                                       [](const ModeEvent& e) { return e.to.kind == ModeKind::Stuck; });
        const double held = *std::max_element(lc.stick_fraction.begin(), lc.stick_fraction.end());
        c.html << "<tr><td>(" << fmt(q[0], 3) << ", " << fmt(q[1], 3) << ", " << fmt(q[2], 3) << ")</td><td>"
               << (stuck ? "stuck as a whole " : held > 0 ? "a contact held " : "sliding ") << fmt(100 * held, 3)
               << "% of the period</td><td>" << fmt(lc.twist[0] / S[0], 7) << ", " << fmt(lc.twist[1] / S[1], 7) << ", "
               << fmt(lc.twist[2] / S[2], 7) << "</td><td>"
               << (r.ok ? fmt(r.twist[0] / S[0], 7) + ", " + fmt(r.twist[1] / S[1], 7) + ", " + fmt(r.twist[2] / S[2], 7)
                        : esc(r.failure))
               << "</td><td>" << fmt(r.order, 3) << "</td><td>"
               << (r.ok && lc.converged ? fmt((lc.twist - r.twist).cwiseQuotient(S).cwiseAbs().maxCoeff(), 3) : std::string("—"))
               << "</td><td>" << fmt(r.error, 2) << "</td></tr>\n";
        if (r.ok && lc.converged) {
            const bool within = (lc.twist - r.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() <= 1e-7 + r.error;
            agree += within;
            stuck_differ += stuck && !within;
        }
    }
    c.html << "</table>\n<p>" << agree << " of " << std::size(qs) << " cycles agree with the reference within 10<sup>-7</sup> "
           << "v<sub>ref</sub> plus its error.";
    if (stuck_differ > 0)
        c.html << " " << stuck_differ << " cycle" << (stuck_differ > 1 ? "s" : "") << " stuck as a whole for part of the "
               << "period differ" << (stuck_differ > 1 ? "" : "s") << " beyond it (the engine breaks away where the "
               << "friction-disk gauge of the needed wrench reaches 1; the regularised part where its creep does).";
    c.html << " The engine's fields assume rigid Coulomb friction.</p>\n";

    // Scenes nobody tuned (study.hpp: sticking_random_scene): the same comparison on seeded random
    // scenes, the engine at its default options.
    const int n = quick ? 12 : 60;
    const double band = 3e2 * LimitCycleOptions{}.integration.rtol, tol = LimitCycleOptions{}.tol;
    int converged = 0, flew = 0, held = 0, stuck = 0, ref_failed = 0, beyond = 0;
    std::vector<std::pair<double, std::uint64_t>> diffs;
    std::vector<double> ref_errors;
    for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(n); ++seed) {
        const RandomStickCase r = random_stick_case(seed);
        converged += r.converged();
        flew += !r.converged() && r.failure.find("would fly") != std::string::npos;
        if (!r.converged()) continue;
        held += r.held > 0;
        stuck += r.held >= 1;
        if (!r.reference_ok) {
            ++ref_failed;
            continue;
        }
        diffs.emplace_back(r.error, seed);
        ref_errors.push_back(r.reference_error);
        beyond += r.error > band + tol + r.reference_error;
    }
    std::sort(diffs.begin(), diffs.end());
    std::sort(ref_errors.begin(), ref_errors.end());
    c.html << "<p><b>Scenes nobody tuned.</b> " << n << " seeded random scenes (thick, thin and point parts; motions on "
           << "all six axes, the largest x or y harmonic rescaled to 0.05–1.2 μg and the heave by 0.5–2.5; one random "
           << "configuration within 3 cm of the centre each; <code>sticking_random_scene</code>), the engine at its default "
           << "options (rtol " << fmt(LimitCycleOptions{}.integration.rtol, 1) << ", cycles to " << fmt(tol, 1)
           << " v<sub>ref</sub>): " << converged << " cycles found";
    if (flew > 0) c.html << ", " << flew << " left the model (a contact's normal force reached zero: the part would fly; said so)";
    c.html << "; " << held << " of them hold a contact for part of the period or longer, " << stuck << " all period. ";
    if (!diffs.empty())
        c.html << "The reference found a cycle on " << diffs.size() << " (its own error estimate: median "
               << fmt(ref_errors[ref_errors.size() / 2], 2) << ", largest " << fmt(ref_errors.back(), 2)
               << " v<sub>ref</sub>); the differences: largest " << fmt(diffs.back().first, 2) << " v<sub>ref</sub> (seed "
               << diffs.back().second << "), median " << fmt(diffs[diffs.size() / 2].first, 2) << "; " << beyond
               << " beyond the engine's bound (the zero band of its slips, " << fmt(band, 1) << ", plus the cycle tolerance) "
               << "plus the reference's error";
    if (ref_failed > 0) c.html << "; on " << ref_failed << " the reference itself found no cycle";
    c.html << ".</p>\n";
}

void section_fields(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    c.html << "<h2>6. The paper's fields</h2>\n";
    struct F {
        const char* scene;
        Vec3 start;
        double duration;
        const char* what;
    };
    const F figs[] = {{"fig1_point", Vec3(0.04, -0.03, 0), 10, "Fig. 1(b): point part, velocity field"},
                      {"fig1", Vec3(-0.04, 0.03, 1.2), 20, "Fig. 1(c)-(f): lines of fixed points at θ = 0, π"},
                      {"fig4", Vec3(0.04, -0.04, 1.0), 20, "Fig. 4: centring and orienting"},
                      {"fig5", Vec3(0.0, -0.04, 1.0), 4, "Fig. 5: transport along y, θ to 0 or π"},
                      {"fig6", Vec3(0.03, 0.03, 0.5), 20, "Fig. 6: rotation"},
                      {"heave_yaw", Vec3(0.03, 0.03, 0.5), 20, "Heave + rocking yaw (z and rz, one frequency)"},
                      {"heave_yaw_point", Vec3(0.03, 0.03, 0), 20, "Heave + rocking yaw, point part"}};
    for (const auto& f : figs) {
        const Scene sc = load_scene((src / "scenes" / (std::string(f.scene) + ".json")).string());
        GridSpec g;
        if (opt.quick) g.nx = g.ny = g.nth = 4;
        if (std::string(f.scene) == "fig5") { g.x0 = -0.03; g.x1 = 0.03; }
        Field field;
        FixedPoints fp;
        Trajectory tr;
        FieldOptions fo;
        fo.threads = opt.threads;
        c.timed(std::string("field ") + f.scene, [&] {
            field = compute_field(sc, g, fo);
            fp = find_fixed_points(sc, field);
            tr = simulate(sc, Dynamics::Full, f.start, Vec3::Zero(), opt.quick ? std::min(f.duration, 4.0) : f.duration, 0.05);
        });
        const bool pt = sc.part.point;
        const std::string n = f.scene;
        {
            // Arrows = twist x one time scale, the longest 0.8 of a grid cell (in x, y and theta).
            double lmax = 0;
            const double dx = std::max(g.dx(), 1e-9), dy = std::max(g.dy(), 1e-9), dth = g.dth();
            for (const auto& p : field.points)
                if (p.converged)
                    lmax = std::max({lmax, std::abs(p.twist[0]) / dx, std::abs(p.twist[1]) / dy, pt ? 0.0 : std::abs(p.twist[2]) / dth});
            const double k = lmax > 0 ? 0.8 / lmax : 0;
            auto o = c.data(n + "_field.dat");
            for (const auto& p : field.points) {
                if (!p.converged) continue;
                o << p.q[0] << ' ' << p.q[1] << ' ' << wrap_angle(p.q[2]) << ' ' << k * p.twist[0] << ' ' << k * p.twist[1] << ' '
                  << (pt ? 0.0 : k * p.twist[2]) << ' '
                  << *std::max_element(p.stick_fraction.begin(), p.stick_fraction.end()) << '\n';
            }
            auto t = c.data(n + "_traj.dat");
            for (const auto& s : tr.samples) t << s.q[0] << ' ' << s.q[1] << ' ' << wrap_angle(s.q[2]) << '\n';
        }
        c.html << scene_heading(f.what, sc.name, n + ".json") << "\n<p>Field on " << field.grid.nx << "×" << field.grid.ny
               << (pt ? "" : "×" + std::to_string(field.grid.nth)) << " configurations (" << fmt(field.seconds, 3)
               << " s); red: full-dynamics run from rest at (" << f.start[0] << ", " << f.start[1]
               << (pt ? "" : ", " + fmt(f.start[2], 3)) << ") for " << (tr.samples.empty() ? 0.0 : tr.samples.back().t)
               << " s" << (tr.stop.reason != StopReason::None ? " — stopped: " + esc(tr.stop.describe()) : std::string())
               << ".</p>\n";
        {
            // A paper figure's run must reach its full duration (a run that stops at once draws a dot).
            const double want = opt.quick ? std::min(f.duration, 4.0) : f.duration;
            const double reached = tr.samples.empty() ? 0.0 : tr.samples.back().t;
            if (tr.stop.reason != StopReason::None || reached < want * (1 - 1e-9))
                c.html << "<p><span class=\"fail\">FAIL: the run from rest stopped at t = " << fmt(reached, 4) << " s of "
                       << fmt(want, 3) << " s" << (tr.stop.reason != StopReason::None ? " (" + esc(tr.stop.describe()) + ")" : "")
                       << "</span></p>\n";
        }
        const std::string F = "'data/" + n + "_field.dat'", T = "'data/" + n + "_traj.dat'";
        const std::string arrows = " w vec head size 0.004,20 lc rgb '#777777' notitle";
        const std::string kFieldSize = "800,640";   // field figures: large enough to read the arrows
        if (pt) {
            c.plot(n + "_xy", "set xlabel 's_x'\nset ylabel 's_y'\nset size ratio -1\nplot " + F + " u 1:2:4:5" + arrows + ", " + T +
                                  " u 1:2 w l lw 2 lc rgb '#c02020' notitle\n",
                   std::string(f.what) + ": s_x–s_y", kFieldSize);
        } else {
            c.plot(n + "_3d", "set xlabel 's_x'\nset ylabel 's_y'\nset zlabel 'θ'\nset view 60,30\nsplot " + F + " u 1:2:3:4:5:6" + arrows +
                                  ", " + T + " u 1:2:3 w l lw 2 lc rgb '#c02020' notitle\n",
                   std::string(f.what) + ": (s_x, s_y, θ)", kFieldSize);
            c.plot(n + "_xy", "set xlabel 's_x'\nset ylabel 's_y'\nplot " + F + " u 1:2:4:5" + arrows + ", " + T + " u 1:2 w l lw 2 lc rgb '#c02020' notitle\n",
                   "s_x–s_y projection", kFieldSize);
            c.plot(n + "_xt", "set xlabel 's_x'\nset ylabel 'θ'\nplot " + F + " u 1:3:4:6" + arrows + ", " + T + " u 1:3 w p pt 7 ps 0.3 lc rgb '#c02020' notitle\n",
                   "s_x–θ projection", kFieldSize);
            c.plot(n + "_yt", "set xlabel 's_y'\nset ylabel 'θ'\nplot " + F + " u 2:3:5:6" + arrows + ", " + T + " u 2:3 w p pt 7 ps 0.3 lc rgb '#c02020' notitle\n",
                   "s_y–θ projection", kFieldSize);
        }
        int stuck = 0, lost = 0, sticks = 0, held_all = 0;
        for (const auto& p : field.points) {
            stuck += p.stop == StopReason::Sticking;
            lost += p.stop == StopReason::ContactLost;
            sticks += p.converged && *std::max_element(p.stick_fraction.begin(), p.stick_fraction.end()) > 0;
            held_all += p.converged && *std::min_element(p.stick_fraction.begin(), p.stick_fraction.begin() + sc.part.contacts()) >= 1;
        }
        c.html << "<p>Configurations where the twist is undefined: " << stuck << " sticking, " << lost << " contact lost. "
               << "Configurations whose cycle sticks (a contact held for part of the period): " << sticks << " of "
               << field.points.size() << "; stuck as a whole all period long (twist exactly zero): " << held_all << ".</p>\n";
        if (sticks > 0) {
            // The largest stick fraction of the three contacts over the cycle, per configuration.
            const std::string SF = "'data/" + n + "_field.dat'";
            c.plot(n + "_stick", pt ? "set xlabel 's_x'\nset ylabel 's_y'\nset size ratio -1\nset cblabel 'stick fraction'\nset cbrange [0:1]\n"
                                      "plot " + SF + " u 1:2:7 w p pt 5 ps 2 palette notitle\n"
                                    : "set xlabel 's_x'\nset ylabel 's_y'\nset zlabel 'θ'\nset view 60,30\nset cblabel 'stick fraction'\n"
                                      "set cbrange [0:1]\nsplot " + SF + " u 1:2:3:7 w p pt 7 ps 1 palette notitle\n",
                   std::string(f.what) + ": fraction of the cycle a contact is held (largest of the contacts)", kFieldSize);
        }
        c.html << "<table><tr><th>fixed point / line</th><th>at (from … to)</th><th>stability</th><th>eigenvalues (real parts)</th></tr>\n";
        for (const auto& p : fp.points) {
            c.html << "<tr><td>point</td><td>(" << fmt(p.q[0], 3) << ", " << fmt(p.q[1], 3) << (pt ? "" : ", " + fmt(p.q[2], 4)) << ")</td><td>"
                   << stability_name(p.stability) << "</td><td>";
            for (int i = 0; i < (pt ? 2 : 3); ++i) c.html << fmt(p.eigenvalues[i].real(), 3) << " ";
            c.html << "</td></tr>\n";
        }
        for (const auto& l : fp.lines) {
            const Vec3 &a = l.points.front(), &b = l.points.back();
            c.html << "<tr><td>line</td><td>(" << fmt(a[0], 3) << ", " << fmt(a[1], 3) << (pt ? "" : ", " + fmt(a[2], 3)) << ") … ("
                   << fmt(b[0], 3) << ", " << fmt(b[1], 3) << (pt ? "" : ", " + fmt(b[2], 3)) << ")</td><td>" << stability_name(l.stability)
                   << "</td><td>";
            for (int i = 0; i < (pt ? 2 : 3); ++i) c.html << fmt(l.eigenvalues[i].real(), 3) << " ";
            c.html << "</td></tr>\n";
        }
        c.html << "</table>\n<p>" << esc(fixed_points_sentence(fp)) << ".</p>\n";
    }
    section_stick_reference(c, src, opt.quick);
}

}  // namespace

// Inverse design (design.hpp): point-part sinks designed, verified, and shown -- the signal, the field
// with its fixed point, and full-dynamics runs from the verification's random starts.
// A design table row's first cells: the target, the verdict (with why it failed), unique, the rate,
// evaluations and cycles.
std::string design_cells(const std::string& target, const DesignSummary& d) {
    return "<tr><td>" + target + "</td><td>" + verdict(d.verified) + (d.verified ? "" : " " + esc(d.failure)) + "</td><td>" +
           (d.unique ? "yes" : "no") + "</td><td>" + fmt(d.rate, 3) + "</td><td>" + std::to_string(d.evaluations) +
           "</td><td>" + std::to_string(d.cycles) + "</td>";
}

// The cell of the part released at the target: how far it is after the hold, marked beyond `allowed`,
// and why its run stopped early (`stop`), if it did.
std::string held_cell(double walked, double allowed, const std::string& from, const std::string& stop) {
    const std::string v = fmt(1e3 * walked, 3);
    return "<td>" + (walked > allowed ? "<span class=\"fail\">" + v + "</span>" : v) + from +
           (stop.empty() ? "" : " (" + esc(stop) + ")") + "</td></tr>\n";
}

void section_design(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    const Scene part = load_scene((src / "scenes" / "fig1_point.json").string());
    DesignOptions o;
    o.lin_limit = 15;
    o.ang_limit = 100;
    o.threads = opt.threads;
    o.seed = opt.seed;
    o.starts = default_starts(part, DesignTarget{});   // (the sink's and the line sink's)
    if (opt.quick) {
        o.local_evaluations = 120;
        o.verify_starts = 6;
    }
    c.html << "<h2>Inverse design</h2>\n<p>Plate motions designed by <code>design()</code> (NLopt COBYLA from "
           << o.starts << " seeded feasible starts, " << o.local_evaluations << " evaluations each) so that "
           << esc(part.name) << "'s point part has its unique stable fixed point at the target, within amplitude limits of "
           << fmt(o.lin_limit, 3) << " m/s² and " << fmt(o.ang_limit, 3) << " rad/s² per harmonic and keeping g + a<sub>z</sub> ≥ "
           << fmt(o.flight_margin, 3) << " g over the plate; each verified on a " << o.verify_grid << "×" << o.verify_grid
           << " grid (one stable fixed point within " << fmt(1e3 * o.fixed_point_tolerance, 3) << " mm) and by "
           << o.verify_starts << " full-dynamics runs from seeded random starts (ending within "
           << fmt(1e3 * o.verify_distance, 3) << " mm), and by a part released at rest at the target still within that "
           << "distance after " << fmt(o.hold, 3) << " s of full dynamics (the last column). Odd harmonics (n = 1, 3) on x, "
              "y, rx, ry make the field odd about the design's centre (a fixed point by construction); adding −α×D to the "
              "linear acceleration moves it onto the target exactly. Tilting in circles cones: the plate turns about z "
              "at a second-order rate the asymptotic field does not see, and the whole field, the sink with it, turns "
              "about the plate's centre; so a sink at D is held to a coning rate of at most (verification distance) / "
              "(2 |D| hold). The same construction pulls a rigid part's position at every orientation (its row: "
              "verified at each of the grid's orientations, by runs from random positions and orientations, and "
              "held; the part may turn on at the sink).</p>\n"
              "<table><tr><th>target</th><th>verified</th><th>unique</th><th>rate [1/s]</th><th>evaluations</th>"
              "<th>cycles</th><th>worst end distance [mm]</th><th>seconds</th>"
              "<th>coning [rad/s]</th><th>from the target, after the hold [mm]</th></tr>\n";
    DesignSummary first;
    Vec2 first_at = Vec2::Zero();
    const Vec2 targets[] = {{0.02, -0.01}, {-0.025, 0.015}};
    int k = 0;
    for (const Vec2& at : targets) {
        DesignTarget t;
        t.at = at;
        const DesignSummary d = design(part, t, o);
        c.html << design_cells("sink (" + fmt(at.x(), 3) + ", " + fmt(at.y(), 3) + ")", d) << "<td>"
               << fmt(1e3 * d.worst_end_distance, 3) << "</td><td>" << fmt(d.seconds, 3) << "</td><td>"
               << fmt(d.coning, 3) << "</td>" << held_cell(d.held.end_distance, o.verify_distance, "", d.held.stop);
        if (k++ == 0) {   // the figures are the first target's
            first = d;
            first_at = at;
        }
    }
    {   // a rigid part's sink: its position, whatever its orientation (the same construction)
        const Scene rigid = load_scene((src / "scenes" / "fig4.json").string());
        DesignTarget t;
        t.at = targets[0];
        const DesignSummary d = design(rigid, t, o);
        c.html << design_cells(esc(rigid.name) + "'s rigid part: sink (" + fmt(t.at.x(), 3) + ", " + fmt(t.at.y(), 3) +
                                   "), any orientation",
                               d)
               << "<td>" << fmt(1e3 * d.worst_end_distance, 3) << "</td><td>" << fmt(d.seconds, 3) << "</td><td>"
               << fmt(d.coning, 3) << "</td>" << held_cell(d.held.end_distance, o.verify_distance, "", d.held.stop);
    }
    {   // a line sink (design.cpp: y and rx, turned and shifted onto the line)
        DesignTarget t;
        t.kind = DesignTargetKind::LineSink;
        t.at = Vec2(0.01, -0.02);
        t.theta = 0.6;
        const DesignSummary d = design(part, t, o);
        const Vec2 nrm(-std::sin(t.theta), std::cos(t.theta));
        const Trajectory hold = simulate(d.scene, Dynamics::Full, Vec3(t.at.x(), t.at.y(), 0), Vec3::Zero(), o.hold, o.hold);
        const double walked = hold.samples.empty() ? std::numeric_limits<double>::quiet_NaN()
                                                   : std::abs((hold.samples.back().q.head<2>() - t.at).dot(nrm));
        c.html << design_cells("line sink through (" + fmt(t.at.x(), 3) + ", " + fmt(t.at.y(), 3) + ") along " +
                                   fmt(t.theta, 3) + " rad", d)
               << "<td>" << fmt(1e3 * d.worst_end_distance, 3) << " (from the line)</td><td>" << fmt(d.seconds, 3)
               << "</td><td>" << fmt(coning_rate(d.scene.plate), 3) << "</td>"
               << held_cell(walked, o.verify_distance, " (from the line)",
                            hold.stop.reason != StopReason::None ? hold.stop.describe() : "");
    }
    c.html << "</table>\n<p>For the sinks the last column is the verification's hold; the line sink's (y and rx "
              "only: no coning) is measured here, released on the line for " << fmt(o.hold, 3) << " s. A distance "
              "beyond the verification's is marked.</p>\n";
    {
        const DesignSummary& d = first;
        const Vec2& at = first_at;
        const std::string n = "design_sink";
        {
            auto o2 = c.data(n + "_signal.dat");
            for (int i = 0; i <= 200; ++i) {
                const double tt = d.scene.plate.T * i / 200;
                Vec3 pdd, wd;
                d.scene.plate.acceleration(tt, pdd, wd);
                o2 << tt << ' ' << pdd.transpose() << ' ' << wd.transpose() << '\n';
            }
        }
        GridSpec g;
        g.nx = g.ny = 11;
        g.nth = 1;
        FieldOptions fo;
        fo.threads = opt.threads;
        const Field f = compute_field(d.scene, g, fo);
        {
            auto o3 = c.data(n + "_field.dat");
            const double scale = 0.004 / std::max(1e-12, [&] {
                double m = 0;
                for (const auto& p : f.points) m = std::max(m, p.twist.head<2>().norm());
                return m;
            }());
            for (const auto& p : f.points)
                o3 << p.q[0] << ' ' << p.q[1] << ' ' << scale * p.twist[0] << ' ' << scale * p.twist[1] << '\n';
            auto o4 = c.data(n + "_runs.dat");
            for (const DesignStartRun& r : d.runs) {
                const Trajectory tr = simulate(d.scene, Dynamics::Full, Vec3(r.x, r.y, 0), Vec3::Zero(), r.seconds, r.seconds / 200);
                for (const Sample& smp : tr.samples) o4 << smp.q[0] << ' ' << smp.q[1] << '\n';
                o4 << "\n\n";
            }
            c.data(n + "_target.dat") << at.x() << ' ' << at.y() << '\n';
        }
        c.plot(n + "_signal", "set xlabel 't [s]'\nset ylabel 'm/s²'\nset y2label 'rad/s²'\nset ytics nomirror\nset y2tics\n"
               "set key outside right\nplot for [i=2:4] 'data/" + n + "_signal.dat' u 1:i w l lw 2 t word('x y z', i-1), "
               "for [i=5:7] 'data/" + n + "_signal.dat' u 1:i axes x1y2 w l dt 2 lw 2 t word('rx ry rz', i-4)\n",
               "The designed signal over one period: the plate's linear (solid) and angular (dashed) acceleration.",
               "800,420");
        c.plot(n + "_field", "set xlabel 's_x [m]'\nset ylabel 's_y [m]'\nset size ratio -1\nset key outside right\n"
               "plot 'data/" + n + "_field.dat' u 1:2:3:4 w vec head size 0.002,20 lc rgb '#777777' t 'field', "
               "'data/" + n + "_runs.dat' u 1:2 w l lc rgb '#3050c0' t 'full dynamics, random starts', "
               "'data/" + n + "_target.dat' u 1:2 w p pt 7 ps 2 lc rgb '#c02020' t 'target'\n",
               "The designed velocity field (arrows, scaled) and the full-dynamics runs of the verification converging "
               "on the target.", "800,640");
    }
}

// A design's options in the report: the defaults with the report's threads and seed; with --quick a
// smaller search and fewer verification runs.
DesignOptions report_design_options(const ReportOptions& opt, int quick_starts, int quick_evaluations, int quick_runs) {
    DesignOptions o;
    o.threads = opt.threads;
    o.seed = opt.seed;
    if (opt.quick) {
        o.starts = quick_starts;
        o.local_evaluations = quick_evaluations;
        o.verify_starts = quick_runs;
    }
    return o;
}

// The orienter (design.cpp's weathervane): a part with a rubber foot turned to one orientation from
// anywhere by a plate that only translates; theta' over a turn and the full-dynamics runs' theta(t).
void section_orient(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    const Scene part = load_scene((src / "scenes" / "foot.json").string());
    const DesignOptions o = report_design_options(opt, 2, 80, 8);
    DesignTarget t;
    t.kind = DesignTargetKind::Orient;
    t.theta = 2.0;
    const DesignSummary d = design(part, t, o);
    const auto mu = part.part.mu;
    c.html << "<h3>Orienting a part</h3>\n<p>" << esc(part.name) << ": Fig. 4's triangle with friction coefficients "
           << fmt(mu[0], 3) << ", " << fmt(mu[1], 3) << ", " << fmt(mu[2], 3)
           << " on its contacts (a rubber foot), target orientation θ = " << fmt(t.theta, 3)
           << " rad, position free. A plate that only translates makes the twist the same at every position "
              "(full dynamics = U-dynamics: no tilt, no coning); with one friction coefficient on every contact it "
              "cannot turn the part at all (friction's torque −(Σ μ<sub>i</sub>N<sub>i</sub>r<sub>i</sub>)×u "
              "vanishes when the normal forces balance friction's moment), with unequal ones it is a weathervane. "
              "Designed on a ring of 12 orientations (" << d.starts << " starts, " << o.local_evaluations
           << " evaluations each), turned onto θ, verified on a ring of " << d.ring_theta.size()
           << " orientations and by " << d.runs.size() << " full-dynamics runs from random starts.</p>\n"
           << "<table><tr><th>target</th><th>verified</th><th>unique</th><th>rate [1/s]</th><th>evaluations</th>"
              "<th>cycles</th><th>worst end angle [rad]</th><th>travel at θ [m/s]</th><th>seconds</th></tr>\n"
           << design_cells("orient " + fmt(t.theta, 3), d) << "<td>"
           << fmt(d.worst_end_distance / o.verify_distance * 0.05, 3) << "</td><td>" << fmt(d.transport_mean.norm(), 3)
           << "</td><td>" << fmt(d.seconds, 3) << "</td></tr>\n</table>\n";
    if (d.ring_theta.empty()) return;
    {
        auto r = c.data("design_orient_ring.dat");
        for (std::size_t k = 0; k <= d.ring_theta.size(); ++k) {
            const std::size_t i = k % d.ring_theta.size();
            r << (k == d.ring_theta.size() ? 2 * kPi : d.ring_theta[i]) << ' ' << d.ring_twist[i][2] << '\n';
        }
        c.data("design_orient_target.dat") << wrap_angle(t.theta) + (wrap_angle(t.theta) < 0 ? 2 * kPi : 0) << " 0\n";
        auto runs = c.data("design_orient_runs.dat");
        for (const DesignStartRun& s : d.runs) {
            IntegrationOptions io;
            io.rtol = 1e-7;   // (the verification's)
            const Trajectory tr = simulate(d.scene, Dynamics::Full, Vec3(s.x, s.y, s.theta), Vec3::Zero(), s.seconds, s.seconds / 200, io);
            double prev = 0, unwrapped = 0;
            for (std::size_t k = 0; k < tr.samples.size(); ++k) {
                const double th = tr.samples[k].q[2];
                unwrapped = k == 0 ? th : unwrapped + wrap_angle(th - prev);
                prev = th;
                // (shown as the distance to the target orientation, in (-pi, pi])
                runs << tr.samples[k].t << ' ' << wrap_angle(unwrapped - t.theta) << '\n';
            }
            runs << "\n\n";
        }
    }
    int stable_zeros = 0;
    for (std::size_t k = 0; k < d.ring_twist.size(); ++k)
        stable_zeros += d.ring_twist[k][2] > 0 && d.ring_twist[(k + 1) % d.ring_twist.size()][2] <= 0;
    c.plot("design_orient_ring", "set xlabel 'θ [rad]'\nset ylabel 'θ′ [rad/s]'\nset xrange [0:2*pi]\nset key outside right\n"
           "plot 'data/design_orient_ring.dat' u 1:2 w lp pt 7 ps 0.5 lw 2 t 'designed: θ′ at the centre', 0 w l lc rgb '#999999' notitle, "
           "'data/design_orient_target.dat' u 1:2 w p pt 7 ps 2 lc rgb '#c02020' t 'target θ'\n",
           "The designed plate motion's turning rate over a full turn of the part, at the centre (the same at every "
           "position of the 7³ grid, to " + fmt(d.transport_spread, 2) + " of v_ref): " + std::to_string(stable_zeros) +
           " stable zero(s) (θ′ falling through zero), the one found at θ = " + fmt(d.fixed_point[2], 4) + " rad.", "800,420");
    int reached = 0;
    for (const DesignStartRun& s : d.runs) reached += s.stop.empty() && s.end_distance <= o.verify_distance;
    c.plot("design_orient_runs", "set xlabel 't [s]'\nset ylabel 'θ − target [rad]'\nset yrange [-pi:pi]\nset key off\n"
           "plot 'data/design_orient_runs.dat' u 1:2 w l lw 1.5\n",
           "The verification's full-dynamics runs from random starts (rtol 1e-7): " + std::to_string(reached) + " of " +
           std::to_string(d.runs.size()) + " end within 0.05 rad of the target.", "800,420");
}

// A rigid part's fixed point (design.cpp): fig4's part at (0.02, -0.01, 0.5). The design starts from a
// half-turn pair and breaks it with rz about its centre where that verifies (break_pair); the table and
// the runs' theta(t) show what the verification found (the target's share of the random starts and any
// competitor's).
void section_fixed_point(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    const Scene part = load_scene((src / "scenes" / "fig4.json").string());
    const DesignOptions o = report_design_options(opt, 2, 150, 10);
    DesignTarget t;
    t.kind = DesignTargetKind::FixedPoint;
    t.at = Vec2(0.02, -0.01);
    t.theta = 0.5;
    const DesignSummary d = design(part, t, o);
    c.html << "<h3>Fixing a rigid part: position and orientation</h3>\n<p>" << esc(part.name)
           << "'s part, target (x, y, θ) = (" << fmt(t.at.x(), 3) << ", " << fmt(t.at.y(), 3) << ", " << fmt(t.theta, 3)
           << "), default limits, " << d.starts << " starts in all, " << o.local_evaluations
           << " evaluations each. What the design reports about how it got there:</p>\n<ul>\n";
    for (const std::string& n : d.notes) c.html << "<li>" << esc(n) << "</li>\n";
    c.html << "</ul>\n<table><tr><th>target</th><th>verified</th><th>unique</th><th>rate [1/s]</th><th>evaluations</th>"
              "<th>cycles</th><th>target's share of the runs</th><th>other stable fixed points (share)</th><th>seconds</th>"
              "<th>from the target, after the hold [mm]</th></tr>\n"
           << design_cells("fixed point (" + fmt(t.at.x(), 3) + ", " + fmt(t.at.y(), 3) + ", " + fmt(t.theta, 3) + ")", d)
           << "<td>" << fmt(d.basin_share, 3) << "</td><td>";
    for (const DesignSummary::Competitor& k : d.competitors)
        c.html << "(" << fmt(k.point.q[0], 4) << ", " << fmt(k.point.q[1], 4) << ", " << fmt(k.point.q[2], 4) << "): "
               << fmt(k.basin_share, 3) << "<br>";
    c.html << "</td><td>" << fmt(d.seconds, 3) << "</td>"
           << held_cell(d.held.end_distance, o.verify_distance, "", d.held.stop) << "</table>\n";
    if (d.runs.empty()) return;
    {
        auto runs = c.data("design_fixed_point_runs.dat");
        IntegrationOptions io;
        io.rtol = 1e-7;   // (the verification's)
        for (const DesignStartRun& s : d.runs) {
            const Trajectory tr =
                simulate(d.scene, Dynamics::Full, Vec3(s.x, s.y, s.theta), Vec3::Zero(), s.seconds, s.seconds / 200, io);
            for (const Sample& smp : tr.samples) {
                double off = wrap_angle(smp.q[2] - t.theta);   // (shown in [-pi/2, 3 pi/2): a half-turn twin at pi)
                if (off < -kPi / 2) off += 2 * kPi;
                runs << smp.t << ' ' << (smp.q.head<2>() - t.at).norm() << ' ' << off << '\n';
            }
            runs << "\n\n";
        }
    }
    // Where the runs ended, counted here: at the target, at each competing fixed point, elsewhere.
    const double ang = 0.05;   // [rad] (the verification's angle tolerance)
    auto ends_at = [&](const DesignStartRun& r, const Vec3& q) {
        return r.stop.empty() && (r.end.head<2>() - q.head<2>()).norm() <= o.verify_distance &&
               std::abs(wrap_angle(r.end[2] - q[2])) <= ang;
    };
    std::string where;
    int accounted = 0;
    const Vec3 goal(t.at.x(), t.at.y(), t.theta);
    int n0 = 0;
    for (const DesignStartRun& r : d.runs) n0 += ends_at(r, goal);
    accounted += n0;
    where = std::to_string(n0) + " of " + std::to_string(d.runs.size()) + " end within " + fmt(1e3 * o.verify_distance, 3) +
            " mm and " + fmt(ang, 3) + " rad of the target";
    for (const DesignSummary::Competitor& k : d.competitors) {
        int n = 0;
        for (const DesignStartRun& r : d.runs) n += !ends_at(r, goal) && ends_at(r, k.point.q);
        accounted += n;
        where += ", " + std::to_string(n) + " at the stable fixed point (" + fmt(k.point.q[0], 4) + ", " + fmt(k.point.q[1], 4) +
                 ") turned " + fmt(wrap_angle(k.point.q[2] - t.theta), 3) + " rad from it";
    }
    where += ", " + std::to_string(static_cast<int>(d.runs.size()) - accounted) + " elsewhere";
    c.plot("design_fixed_point_runs",
           "set xlabel 't [s]'\nset ylabel 'θ − target [rad]'\nset y2label 'distance from the target [m]'\n"
           "set ytics nomirror\nset y2tics\nset yrange [-pi/2:3*pi/2]\nset key outside right\n"
           "plot 'data/design_fixed_point_runs.dat' u 1:3 w l lw 1.5 lc rgb '#3050c0' t 'θ − target', "
           "'' u 1:2 axes x1y2 w l lw 1 lc rgb '#c08020' t 'distance'\n",
           "The verification's full-dynamics runs from random (x, y, θ) (rtol 1e-7; angles shown from −π/2 to 3π/2): " +
               where + (d.verified ? "." : "; the design failed verification: " + d.failure + "."),
           "800,420");
}

void write_report(const ReportOptions& opt) {
    if (opt.out.empty()) throw std::runtime_error("report: no output folder");
    check_sections(opt.sections);
    Ctx c;
    c.dir = opt.out;
    fs::create_directories(c.dir / "data");
    // The page appears complete or not at all: an older page goes first (a killed run must not leave it
    // beside new figures), the new one is written to a temporary and renamed at the end.
    fs::remove(c.dir / "index.html");
    const fs::path src = opt.source_dir;
    const auto t0 = std::chrono::steady_clock::now();
    auto wanted = [&](const char* n) {
        return opt.sections.empty() || std::find(opt.sections.begin(), opt.sections.end(), n) != opt.sections.end();
    };
    std::string left_out;
    for (const auto& n : report_section_names())
        if (!wanted(n.c_str())) left_out += (left_out.empty() ? "" : ", ") + n;
    if (wanted("derivation")) c.timed("derivation", [&] { section_derivation(c); });
    if (wanted("kernels")) c.timed("kernel equivalence", [&] { section_kernels(c, opt.seed); });
    if (wanted("proofs")) section_proofs(c, opt);
    if (wanted("fig3")) c.timed("Fig. 3", [&] { section_fig3(c, src); });
    if (wanted("fields")) section_fields(c, src, opt);
    if (wanted("design")) c.timed("inverse design", [&] { section_design(c, src, opt); });
    if (wanted("orient")) c.timed("orienter", [&] { section_orient(c, src, opt); });
    if (wanted("fixed-point")) c.timed("rigid fixed point", [&] { section_fixed_point(c, src, opt); });
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    // KaTeX from Debian's libjs-katex, copied beside the report when present.
    std::string katex;
    const fs::path kdir = "/usr/share/javascript/katex";
    if (fs::exists(kdir / "katex.min.js")) {
        fs::copy(kdir, c.dir / "katex", fs::copy_options::recursive | fs::copy_options::overwrite_existing);
        katex = "<link rel=\"stylesheet\" href=\"katex/katex.min.css\"><script src=\"katex/katex.min.js\"></script>"
                "<script src=\"katex/contrib/auto-render.js\"></script><script>document.addEventListener('DOMContentLoaded',"
                "function(){renderMathInElement(document.body,{delimiters:[{left:'$$',right:'$$',display:true}],throwOnError:false});});</script>\n";
    }
    std::ostringstream html;
    html << "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>plate: verification report</title>\n" << kErrorTrap << kStyle << katex
         << "</head><body>\n<h1>Sliding manipulation on a 6-DoF plate: verification report</h1>\n";
    html << "<p>Every number below was computed by this run. Seed " << opt.seed << (opt.quick ? " (quick mode)" : "")
         << "; machine: " << esc(machine_description()) << "; total "
         << fmt(total, 4) << " s." << (left_out.empty() ? "" : " Sections left out of this run (--sections): " + esc(left_out) + ".")
         << "</p>\n<table><tr><th>part</th><th>seconds</th></tr>\n";
    for (const auto& [w, s] : c.timings) html << "<tr><td>" << esc(w) << "</td><td>" << fmt(s, 4) << "</td></tr>\n";
    html << "</table>\n" << c.html.str();
    // The speed-accuracy study (plate bench) keeps its section between the markers.
    html << kSpeedBegin;
    const fs::path speed = c.dir / "data" / "speed_section.html";
    if (fs::exists(speed)) html << std::ifstream(speed).rdbuf();
    else html << "<h2>Speed and accuracy</h2><p>Not run yet: <code>plate bench --out " << esc(opt.out)
              << "</code> writes this section (work-precision charts, failure maps, limit-cycle solvers, model hierarchy).</p>\n";
    html << kSpeedEnd << "\n";
    // The peer engines' study (bench/peers/study.py) keeps its section between these.
    html << kPeersBegin;
    const fs::path peers = c.dir / "data" / "peers_section.html";
    if (fs::exists(peers)) html << std::ifstream(peers).rdbuf();
    else html << "<h2>Side by side with Bullet, ODE and MuJoCo</h2><p>Not run yet: <code>bench/peers/study.py --out " << esc(opt.out)
              << "</code> writes this section (the same questions to the engines found at build time and to plate, "
                 "error against CPU time).</p>\n";
    html << kPeersEnd << "\n";
    // The campaigns' scaling study (bench/scaling.py) keeps its section between these.
    html << kCampaignsBegin;
    const fs::path campaigns = c.dir / "data" / "campaigns_section.html";
    if (fs::exists(campaigns)) html << std::ifstream(campaigns).rdbuf();
    else html << "<h2>Campaigns</h2><p>Not run yet: <code>bench/scaling.py --out " << esc(opt.out)
              << "</code> writes this section (strong and weak scaling of <code>plate sweep</code> over threads and MPI ranks, "
                 "load balance, the cost of a 1 000-core campaign).</p>\n";
    html << kCampaignsEnd << "\n" << kPageCheck << "</body></html>\n";
    write_file_atomic((c.dir / "index.html").string(), [&](std::ostream& o) { o << html.str(); });
}

const std::vector<std::string>& report_section_names() {
    static const std::vector<std::string> names = {"derivation", "kernels", "proofs", "fig3",
                                                   "fields", "design", "orient", "fixed-point"};
    return names;
}

void check_sections(const std::vector<std::string>& sections) {
    const auto& names = report_section_names();
    for (const auto& n : sections) {
        if (std::find(names.begin(), names.end(), n) != names.end()) continue;
        std::string all;
        for (const auto& m : names) all += (all.empty() ? "" : ", ") + m;
        throw std::invalid_argument("'" + n + "' is not a section (" + all + ")");
    }
}

std::string collinear_sentence(const std::vector<double>& conds, const std::vector<double>& gaps, double singular) {
    if (conds.size() < 2) return "Too few contact spreads to say how A's conditioning grows.";
    double grow = 1e300, shrink = 1e300;   // the smallest factor per tenth of e/L
    for (std::size_t i = 1; i < conds.size(); ++i) {
        grow = std::min(grow, conds[i] / conds[i - 1]);
        if (gaps[i] > 0) shrink = std::min(shrink, gaps[i - 1] / gaps[i]);
    }
    std::ostringstream o;
    o.precision(2);
    if (grow >= 5)
        o << "A's condition number grows at least " << grow << "x per tenth of e/L (like L/e)";
    else
        o << "A's condition number does not grow like L/e here: at least " << grow << "x per tenth of e/L";
    o << (singular < 1e-12 ? " and A is singular at e = 0" : ", and A is not singular at e = 0 (check)");
    if (shrink >= 5)
        o << "; the two twists' wrenches approach each other at least " << shrink
          << "x per tenth: the limit surface develops a vertex.";
    else
        o << "; the two twists' wrenches do not approach each other like e (at least " << shrink << "x per tenth).";
    return o.str();
}

std::string scene_heading(const std::string& title, const std::string& scene_name, const std::string& file) {
    return "<h3>" + esc(title) + " (<code>" + esc(scene_name) + "</code>, <code>scenes/" + esc(file) + "</code>)</h3>";
}

std::string observation1_sentence(int valid, int converged, int unique, int attracting) {
    if (valid <= 0) return "No thick case stayed in the model, so this campaign says nothing on Observation 1.";
    if (converged == valid && unique == valid && attracting == valid)
        return "In this campaign every cycle found was unique and attracting (Observation 1), in all " +
               std::to_string(valid) + " cases.";
    std::string s = "Observation 1 does not hold in this campaign for every case: of " + std::to_string(valid) + " cases, ";
    std::string parts;
    auto add = [&](int bad, const char* what) {
        if (bad <= 0) return;
        if (!parts.empty()) parts += ", ";
        parts += std::to_string(bad) + " " + what;
    };
    add(valid - converged, "reached no cycle");
    add(converged - unique, "reached another cycle from other initial twists");
    add(converged - attracting, "had a Floquet multiplier of modulus 1 or more");
    return s + parts + ".";
}

}  // namespace plate::report
