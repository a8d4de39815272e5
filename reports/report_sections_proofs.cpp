// The report's sections on the model and its proofs: 1. the symbolic derivation, 2. the generated
// kernels against the hand-written reference, 3. Theorem 1 (contraction, periodicity), 4. the limit
// surfaces and collinear contacts, 5. Observation 1 (Fig. 3).
#include "report_sections.hpp"

#include "plate/scene_io.hpp"
#include "plate/study.hpp"
#include "derivation.hpp"
#include "theorem1.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace plate::report {
namespace fs = std::filesystem;
using namespace html;

void section_derivation(Ctx& c) {
    const symbolic::Derivation d = symbolic::derive();   // run here: every line below is this run's
    c.html << c.heading("1. Symbolic derivation", "derivation")
           << "<p>Derived with GiNaC from frames, contact kinematics, Coulomb "
              "forces and Newton–Euler (<code>symbolic/derivation.cpp</code>), time derivatives by a jet rule; each printed "
              "equation compared with the derived one:</p>\n<table><tr><th>equation</th><th>verdict</th><th>printed</th>"
              "<th>derived</th><th>why</th></tr>\n";
    int differ = 0;
    for (const auto& f : d.findings) {
        differ += !f.agrees;
        c.html << "<tr><td>" << esc(f.equation) << "</td><td>" << c.paper_check(f.equation, f.agrees) << "</td><td><code>"
               << esc(f.printed) << "</code></td><td><code>" << esc(f.derived) << "</code></td><td>" << esc(f.reason)
               << "</td></tr>\n";
    }
    c.html << "</table>\n<p>" << d.findings.size() << " comparisons, " << differ << " differ.</p>\n<h3>Derived equations</h3>\n";
    std::istringstream in(symbolic::latex_report(d));
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("\\paragraph{", 0) != 0) continue;
        const auto close = line.find("}");
        const std::string title = line.substr(11, close - 11);
        const auto a = line.find('$', close), b = line.rfind('$');
        c.html << "<h4>" << esc(title) << "</h4><div class=\"math\">$$" << esc(line.substr(a + 1, b - a - 1)) << "$$</div>\n";
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
            worst = std::max({worst, (g.qdd - f.qdd).head<2>().norm() / sc.g,
                              std::abs(g.qdd[2] - f.qdd[2]) * sc.part.rho() / sc.g, (g.n - f.n).norm() / mg});
        }
    }
    c.html << c.heading("2. Generated kernels against the hand-written reference", "kernels")
           << "<table><tr><th>states</th><th>parts</th>"
              "<th>worst difference (relative to g, m g)</th><th>bound</th><th>verdict</th></tr><tr><td>"
           << n << "</td><td>thick, thin, point</td><td>" << fmt(worst, 3) << "</td><td>1e-12</td><td>"
           << c.verdict("generated kernels equal the hand-written reference within 1e-12", worst < 1e-12)
           << "</td></tr></table>\n";
}

namespace {

// V per period, log scale: a few thin cases and the worst thick one.
void plot_V(Ctx& c, const proofs::ContractionSummary& thin, const proofs::ContractionSummary& thick) {
    auto o = c.data("V.dat");
    std::vector<const proofs::ContractionCase*> show;
    for (const auto& d : thin.details)
        if (d.valid && show.size() < 5) show.push_back(&d);
    const int thin_shown = static_cast<int>(show.size());
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
    const int cols = static_cast<int>(show.size());
    std::string s = "set logscale y\nset format y '10^{%L}'\nset xlabel 'period'\nset ylabel 'V / V_0'\nset key top right\nplot ";
    for (int i = 0; i < cols; ++i)
        s += std::string(i ? ", " : "") + "'data/V.dat' u 1:" + std::to_string(i + 2) + " w lp pt 7 ps 0.4 t '" +
             (i >= thin_shown ? "thick, seed " : "thin, seed ") + std::to_string(show[i]->seed) + "'";
    // The caption says what the thin curves show: the largest per-period factor of |xi_rel|, up to
    // the period where V reaches 1e-16 V0 (rounding).
    double worst_factor = 0;
    for (int i = 0; i < thin_shown; ++i) {
        const auto& V = show[i]->V_periods;
        for (std::size_t k = 1; k < V.size() && V[k - 1] > 1e-16 * show[i]->V0; ++k)
            worst_factor = std::max(worst_factor, std::sqrt(V[k] / V[k - 1]));
    }
    c.plot("lyapunov_V", s + "\n",
           "V(t) = ½|ξ<sub>rel</sub>|² at period boundaries, log scale. " + contraction_caption(thin_shown, worst_factor) +
               (cols > thin_shown ? " The worst thick case shown last." : ""));
}

// Theorem 1 on thin parts and the same campaign beyond it on thick ones: the table, the tie to the
// dynamics, Observation 1 for the thick parts, and V per period.
void proofs_contraction(Ctx& c, const ReportOptions& opt, int n_thin, int n_thick) {
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
    c.html << c.heading("3. Theorem 1: contraction of the relative twist (Appendix C)", "theorem1")
           << "<p>Two copies of a random part at a random configuration, from random twists, integrated on one step "
              "sequence; V = ½|ξ<sub>rel</sub>|² in scaled coordinates (ξ<sub>θ</sub> = ρω). A rise of V between steps "
              "is compared with the bound on its integration error, |ξ<sub>rel</sub>|·2√3δ + 6δ², δ = rtol (v<sub>ref</sub> "
              "+ |ξ|) (the controller's acceptance test on the scaled state). Floquet multipliers: eigenvalues of the "
              "period map's Jacobian at the cycle (central differences). Uniqueness: four more initial twists reach the "
              "same cycle start within 10<sup>-6</sup> v<sub>ref</sub>. The worst change of V between steps over its bound is "
              "signed: ≤ 1 passes, below 0 V fell at every step.</p>\n<table><tr><th>parts</th><th>cases</th><th>in model"
              "</th><th>V never rises beyond error</th><th>worst change of V / bound</th><th>V → 0</th><th>median contraction / "
              "period"
              "</th><th>max Floquet |λ|</th><th>unique cycle</th><th>counter-examples (seeds)</th><th>verdict</th></tr>\n";
    bool theorem = true;
    auto row = [&](const char* name, const proofs::ContractionSummary& s) {
        std::string ce;
        for (std::size_t i = 0; i < s.counterexamples.size() && i < 8; ++i)
            ce += (i ? ", " : "") + std::to_string(s.counterexamples[i]);
        if (s.counterexamples.size() > 8) ce += ", …";
        const bool observation1 = s.valid > 0 && s.converged == s.valid && s.unique == s.valid && s.floquet_below_one == s.valid;
        c.html << "<tr><td>" << name << "</td><td>" << s.cases << "</td><td>" << s.valid << "</td><td>" << s.monotone
               << "</td><td>" << (s.valid > 0 ? fmt(s.worst_increase, 3) + " (seed " + std::to_string(s.worst_seed) + ")" : "–")
               << "</td><td>" << s.converged << "</td><td>" << fmt(s.median_rate, 3) << "</td><td>"
               << fmt(s.max_spectral_radius, 3) << "</td><td>" << s.unique << "</td><td>" << (ce.empty() ? "none" : ce)
               << "</td><td>";
        if (theorem)
            c.html << "Theorem 1: " << c.verdict("Theorem 1, thin parts", s.passed());
        else   // beyond the theorem V may rise: an observation, not a verdict
            c.html << "V rose beyond its error bound in " << s.valid - s.monotone << " of " << s.valid
                   << " cases (observed, no verdict); Observation 1: " << c.verdict("Observation 1, thick parts", observation1);
        c.html << "</td></tr>\n";
    };
    theorem = true;
    row("thin (Theorem 1)", thin);
    theorem = false;
    row("thick (beyond it)", thick);
    c.html << "</table>\n<p>These checks hold for any Coulomb friction with velocity-independent normal forces: they are "
              "tied to the dynamics at "
           << thin.tie.samples
           << " sampled states of the thin parts, where the normal forces must "
              "equal an independent solve of the part's statics and m q'' + b~ the limit-surface wrench (39) of the relative "
              "twist, both to "
           << fmt(proofs::kTieTolerance, 1) << " m g: worst " << fmt(thin.tie.worst_statics, 2) << " and "
           << fmt(thin.tie.worst_wrench, 2) << " m g, "
           << c.verdict("thin parts' dynamics tied to statics and the limit surface", thin.tie.passed(), "pass", thin.tie.failure)
           << " (a wrong normal force, a swapped lever arm and a wrong mu on one contact each fail it: test).</p>\n";
    c.html << "<p>Thick parts are outside Theorem 1: V may rise (the normal forces depend on the twist). "
           << esc(observation1_sentence(thick.valid, thick.converged, thick.unique, thick.floquet_below_one))
           << (thick.monotone < thick.valid
                   ? " The seeds above reproduce the " + std::to_string(thick.valid - thick.monotone) + " cases where V rose."
                   : std::string(" V never rose beyond its error bound in this campaign."))
           << "</p>\n";
    plot_V(c, thin, thick);
}

// Appendix D: the cycle repeats with period T.
void proofs_periodicity(Ctx& c, const ReportOptions& opt) {
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
              "<th>verdict</th></tr><tr><td>"
           << n << "</td><td>" << fmt(worst1, 3) << "</td><td>" << fmt(worst2, 3) << "</td><td>1e-8</td><td>"
           << c.verdict("periodicity of the cycle (Appendix D)", n > 0 && ok == n) << "</td></tr></table>\n";
}

// Limit surfaces (Appendix B): the campaign's table and one thin part's surface.
void proofs_limit_surfaces(Ctx& c, const ReportOptions& opt, int n_surf) {
    proofs::LimitSurfaceCampaign ls;
    c.timed("limit surfaces", [&] { ls = proofs::check_limit_surfaces(n_surf, opt.seed); });
    c.html << c.heading("4. Limit surfaces (Appendix B)", "limit-surfaces")
           << "<p>Wrenches of random thin parts sampled on 300 twist directions; "
              "all pairs tested. Maximum work: ξ<sub>i</sub>·w<sub>j</sub> ≥ ξ<sub>i</sub>·w<sub>i</sub> (convex surface, twist "
              "normal to it); (40): (ξ<sub>i</sub>−ξ<sub>j</sub>)·(w<sub>i</sub>−w<sub>j</sub>) ≤ 0; no vertices: distinct "
              "directions give distinct wrenches; no flat faces: the max-work inequality is strict between distinct "
              "directions.</p>\n"
              "Every margin is signed, of Σ μN: the inequality held by that much at the closest pair (negative: violated).</p>\n"
              "<table><tr><th>parts</th><th>convex and normal (by construction)</th><th>max-work margin (by "
              "construction)</th><th>(40) margin (by construction)</th><th>strictly convex</th><th>smallest strict margin"
              "</th><th>smallest wrench separation</th><th>on the friction set</th><th>support-point margin</th><th>inside "
              "margin</th><th>verdict</th></tr><tr><td>"
           << ls.parts << "</td><td>" << ls.convex << "</td><td>" << fmt(ls.max_work_margin, 3) << "</td><td>"
           << fmt(ls.monotonicity_margin, 3) << "</td><td>" << ls.strict << "</td><td>" << fmt(ls.min_strict_margin, 3)
           << "</td><td>" << fmt(ls.min_separation, 3) << "</td><td>" << ls.on_set << "</td><td>" << fmt(ls.support_margin, 2)
           << "</td><td>" << fmt(ls.outside_margin, 2) << "</td><td>"
           << c.verdict("limit surfaces strictly convex, on the friction set", ls.passed())
           << "</td></tr></table>\n<p>Maximum work and (40) hold by construction: for any wrench of "
              "the form −Σ c<sub>i</sub> G<sub>i</sub> v<sub>i</sub>/|v<sub>i</sub>| with c<sub>i</sub> ≥ 0 (Cauchy-Schwarz), so "
              "a kernel fed a wrong μ or lever arm passes them. What can fail: strict convexity (collinear contacts fail it: "
              "the surface gets a vertex, below), and each part's friction set built independently (every "
              "force of magnitude ≤ μ<sub>i</sub>N<sub>i</sub> at each contact, N from the part's statics, each disk's rim "
              "sampled at 720 points): the kernel's wrench for ξ must be the set's support point in −ξ and inside the set "
              "(margins ≥ −1e-12 pass; a wrong μ or lever arm "
              "fails it: test).</p>\n<p>Each part's dynamics tied to its surface at "
           << ls.tie.samples << " states (statics and wrench, as above): worst " << fmt(ls.tie.worst_statics, 2) << " and "
           << fmt(ls.tie.worst_wrench, 2) << " m g"
           << ": " << c.verdict("random parts' dynamics tied to their limit surfaces", ls.tie.passed(), "pass", ls.tie.failure)
           << ".</p>\n";
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
        c.plot("limit_surface",
               "set xlabel 'F_x / Σ μN'\nset ylabel 'F_y / Σ μN'\nset zlabel 'τ/(ρ Σ μN)'\nset view 60,30\n"
               "splot 'data/surface.dat' w p pt 7 ps 0.25 lc rgb '#3060a0' notitle\n",
               "Limit surface of a random thin part: the wrench −∇P(ξ) for 2500 twist directions.");
    }
}

// Collinearity: conditioning of A as the third contact approaches the line of the other two.
void proofs_collinear(Ctx& c, const ReportOptions& opt) {
    c.html << "<h3>Invertibility of A and collinear contacts</h3>\n<p>The third contact approaches the line of the "
              "other two; two distinct twists (pure y-translation, and one with a spin that keeps every contact moving along "
              "+y) are compared by their wrenches.</p>\n"
              "<table><tr><th>contacts (−L,0), (L,0), (0,e), e/L</th><th>cond(A), dimensionless</th><th>wrench gap / Σ μN</th>"
              "<th>convex and normal (by construction)</th></tr>\n";
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
        c.html << "<tr><td>" << e << "</td><td>"
               << (e > 0 ? fmt(cond.max_condition, 3) : "singular (σ_min/σ_max = " + fmt(cond.min_singular, 2) + ")")
               << "</td><td>" << gap << "</td><td>" << cv << "</td></tr>\n";
    }
    c.html << "</table>\n<p>" << esc(collinear_sentence(conds, gaps, singular)) << "</p>\n";
}

}   // namespace

void section_proofs(Ctx& c, const ReportOptions& opt) {
    const int n_thin = opt.quick ? 24 : 10000, n_thick = opt.quick ? 8 : 1000, n_surf = opt.quick ? 4 : 200;
    proofs_contraction(c, opt, n_thin, n_thick);
    proofs_periodicity(c, opt);
    proofs_limit_surfaces(c, opt, n_surf);
    proofs_collinear(c, opt);
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
    // The two runs' twists at each period boundary, compared (scaled: (v, v, v / rho) is v_ref).
    std::vector<Vec3> ends[2];
    for (const auto* p : {&a, &b}) {
        for (const auto& s : p->path)
            if (std::abs(std::remainder(s.t, sc.plate.T)) < 1e-12) ends[p == &b].push_back(s.qd);
        auto o = c.data(p == &a ? "fig3a.dat" : "fig3b.dat");
        for (const auto& s : p->path) o << s.qd[0] << ' ' << s.qd[1] << ' ' << s.qd[2] << ' ' << s.t << '\n';
        auto m = c.data(p == &a ? "fig3a_T.dat" : "fig3b_T.dat");
        for (const auto& s : p->path)
            if (std::abs(std::remainder(s.t, sc.plate.T)) < 1e-12) m << s.qd[0] << ' ' << s.qd[1] << ' ' << s.qd[2] << '\n';
    }
    if (ends[0].empty() || ends[1].empty()) throw std::runtime_error("Fig. 3: no period boundary recorded");
    const std::size_t last = std::min(ends[0].size(), ends[1].size()) - 1;
    auto gap = [&](std::size_t k) {
        const Vec3 d = ends[0][k] - ends[1][k];
        return std::sqrt(d.head<2>().squaredNorm() + std::pow(sc.part.rho() * d[2], 2)) / v;
    };
    c.html << c.heading("5. Observation 1 (Fig. 3)", "fig3")
           << "<p>Scene <code>fig3_random</code> at (0.01, −0.01, 0.5): two initial "
              "twists, ten periods of the reduced U-dynamics; open circles every T.</p>\n";
    c.plot("fig3",
           "set xlabel 'ṡ_x [m/s]'\nset ylabel 'ṡ_y [m/s]'\nset zlabel 'θ̇ [rad/s]'\nset view 60,40\n"
           "splot 'data/fig3a.dat' u 1:2:3 w l lc rgb '#c03030' t 'start 1', 'data/fig3b.dat' u 1:2:3 w l lc rgb '#3050c0' t "
           "'start 2', "
           "'data/fig3a_T.dat' w p pt 6 lc rgb '#c03030' notitle, 'data/fig3b_T.dat' w p pt 6 lc rgb '#3050c0' notitle\n",
           fig3_caption(static_cast<int>(std::min(ends[0].size(), ends[1].size())) - 1, gap(0), gap(last)));
}

}   // namespace plate::report
