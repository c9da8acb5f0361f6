// How swirl's OpenMP threads wait between parallel passes.
//
// A libgomp thread that reaches the end of a parallel loop spins (300 000
// iterations by default, about a millisecond) before it sleeps. On a machine
// where another process keeps a core busy, the spinning thread takes the time
// slice that its partner needs to finish its block, and every one of the
// step's few dozen passes then waits for the scheduler: 2 threads ran far
// below one thread's speed (docs/performance.md, "a busy machine"). A short
// spin keeps the quick hand-over on a quiet machine and gives the core away
// under load.
//
// libgomp reads its settings once, when it is loaded, so swirl sets
// GOMP_SPINCOUNT and executes itself again, before anything else happens —
// unless the user chose a policy (OMP_WAIT_POLICY or GOMP_SPINCOUNT set), or
// the re-execution fails (then swirl runs on with libgomp's defaults).
#pragma once

namespace swirl::cli {

// The spin count swirl asks for (iterations of libgomp's wait loop).
inline constexpr const char* kSpinCount = "10000";

// Re-executes the program with GOMP_SPINCOUNT = kSpinCount unless a wait
// policy is set already; returns only when it did not re-execute.
void adopt_thread_waiting(char** argv);

}  // namespace swirl::cli
