// plate sweep: a campaign over parameters (resumable; shared over mpirun ranks), a table per case.
#include "commands.hpp"

#include "plate/farm.hpp"
#include "plate/output.hpp"
#include "plate/sweep.hpp"

#include <exception>
#include <iostream>
#include <memory>
#include <string>

namespace plate::cli {
namespace {

struct SweepArgs : Options {
    std::string campaign, out;
    int threads = 0;
    explicit SweepArgs(CLI::App& app)
        : Options(app, "sweep", "a campaign over parameters (resumable; shared over mpirun ranks), a table per case",
                  "Runs a campaign (see campaigns/ and sweep/include/plate/sweep.hpp): one case per parameter\n"
                  "value set, each computing what the campaign asks (twists, a field summary, fixed points,\n"
                  "a design). Every finished case is appended to DIR/journal.jsonl and fsync'd: a killed run\n"
                  "loses only the cases in flight, and the same command resumes it. When every case is done:\n"
                  "DIR/table.csv and DIR/table.jsonl (one row per case, full precision; a failed case has\n"
                  "status failed and its reason), DIR/timing.csv and DIR/summary.svg. Under `mpirun -np N` the\n"
                  "cases are shared over the ranks (one at a time, as workers free up), --threads each; the\n"
                  "table is the same, bit for bit. A JSON summary goes to stdout.\n") {
        scene_file(campaign, "CAMPAIGN", "the campaign file (JSON, see campaigns/)");
        text("--out", out, "DIR", "the campaign's folder; required");
        whole("--threads", threads, 0, 256, "threads (per MPI rank; 0: the cores over the node's ranks)");
    }
};

int cmd_sweep(const SweepArgs& a, Io& cio) {
    if (!a.has("--out")) throw UsageError("missing --out DIR");
    std::unique_ptr<sweep::Farm> farm;
    if (sweep::mpi_launched()) {
        if (!sweep::mpi_built())
            throw UsageError(
                "started by an MPI launcher with several ranks, but this plate was built without MPI: "
                "every process would run the whole campaign (rebuild with libopenmpi-dev, or run it alone)");
        farm = sweep::mpi_farm(a.threads);
    } else {
        farm = sweep::thread_farm(a.threads);
    }
    sweep::SweepOptions o;
    o.out = a.out;
    ProgressPrinter prog{"sweep"};
    prog.to = farm->root() && &cio.err == &std::cerr && progress_wanted() ? &cio.err : nullptr;
    o.progress = std::ref(prog);
    sweep::SweepSummary s;
    try {
        s = sweep::run_sweep(a.campaign, o, *farm);
    } catch (const sweep::Reported&) {   // bad input, which rank 0 reports; every rank returns 2, rank 0
        farm->barrier();                 // first (the launcher ends the job at the first failed rank)
        return 2;
    } catch (const InputError& e) {
        cio.err << "plate sweep: " << e.what() << std::endl;
        farm->barrier();
        return 2;
    } catch (const std::exception& e) {
        cio.err << "plate sweep: error on rank " << farm->rank() << ": " << e.what() << std::endl;
        farm->abort(1);
        return 1;
    }
    if (!farm->root()) return 0;
    const nlohmann::json j = sweep::sweep_summary_json(a.campaign, a.out, s);
    cio.out << j.dump(2) << std::endl;
    return 0;
}

}   // namespace

Command add_sweep(CLI::App& app) { return make_command<SweepArgs>(app, cmd_sweep); }

}   // namespace plate::cli
