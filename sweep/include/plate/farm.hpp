// Sharing independent tasks (a campaign's cases) over threads, or over MPI ranks and threads within
// each (issue 20). The tasks are handed out one at a time as workers become free (dynamic self-
// scheduling: cases differ 100x in cost, a sticking cycle being slower than a sliding one), and the
// results return to rank 0, which alone writes files. A task's result does not depend on where it
// ran, so the results are the same, bit for bit, whatever the ranks and threads.
#pragma once

#include "plate/tasks.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace plate::sweep {

class Farm {
public:
    virtual ~Farm() = default;
    virtual int rank() const { return 0; }
    virtual int ranks() const { return 1; }
    bool root() const { return rank() == 0; }
    // Threads computing tasks, over all ranks (on rank 0, once run() has started).
    virtual int workers() const = 0;
    virtual std::string describe() const = 0;   // "2 ranks x 1 thread"
    // Rank 0's `text` to every rank (collective).
    virtual void broadcast(std::string& text) = 0;
    // Collective. On rank 0: work(i) runs once for every i of `todo`, on some rank's thread, and
    // done(i, result) is called on rank 0 for each, one call at a time, in the order they finish.
    // On the other ranks `todo` and `done` are not used: they compute what rank 0 sends. Returns
    // when every task is done. `work` must not throw (a failure is a result).
    virtual void run(const std::vector<int>& todo, const std::function<std::string(int)>& work,
                     const std::function<void(int, const std::string&)>& done) = 0;
    // Waits for every rank (collective); threads: returns at once.
    virtual void barrier() {}
    // Ends every rank at once with exit code `code` (after an error on one of them); threads: no-op.
    virtual void abort(int /*code*/) {}
};

// Threads of this process (0: all cores).
std::unique_ptr<Farm> thread_farm(int threads);

// The farm as a TaskRunner (plate/tasks.hpp), for a field's planes or a design's starts: the tasks are
// shared like a campaign's cases, then rank 0 broadcasts every result, so every rank gets every
// done(i, ...) and all ranks take the same path afterwards. Collective: every rank calls it with the
// same n. The farm must outlive the runner.
TaskRunner farm_tasks(Farm& farm);

// This program was built with MPI (Open MPI found at configure time).
bool mpi_built();
// The process was started by an MPI launcher with more than one rank (mpirun -np N, N > 1), read
// from the launcher's environment (OMPI_COMM_WORLD_SIZE, PMI_SIZE, PMIX_SIZE...). A program started
// alone does not initialise MPI at all.
bool mpi_launched();
// The ranks of MPI_COMM_WORLD, `threads` threads each (0: the node's cores over its ranks). Initialises
// MPI (thread level FUNNELED: only each rank's main thread calls MPI) and finalises it when destroyed.
// Throws std::runtime_error when the program was built without MPI.
std::unique_ptr<Farm> mpi_farm(int threads);

}   // namespace plate::sweep
