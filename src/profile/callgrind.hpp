// The software route to instruction-level statistics, for machines without performance counters:
// run the workload under valgrind's callgrind with its branch predictor simulation (--branch-sim=yes)
// and read the totals it collected. Instructions are exact counts of the instructions executed;
// mispredictions are those of callgrind's small predictor (cachegrind's cg_branchpred.c: 16,384 2-bit
// counters indexed by 7 address bits and the last 7 branch outcomes; a 512-entry last-target table for
// indirect branches), not of the host processor's, so they compare code with code rather than predict
// a machine. There are no cycles.
#pragma once

#include <istream>
#include <atomic>
#include <string>
#include <vector>

#include "event_counts.hpp"

namespace cellrt::profile {

struct CallgrindOptions {
    // Collect only inside calls of these functions (callgrind --toggle-collect patterns, * and ?
    // wildcards, matched against demangled names); empty: collect everything instrumented.
    std::vector<std::string> toggle_collect;
    // false: instrumentation starts off and the program turns it on around the region it wants
    // (start_instrumentation/stop_instrumentation), which also keeps the rest of it fast.
    bool instrument_at_start = true;
    // Polled while valgrind runs: once true, the run is killed, its files removed, and run_callgrind
    // throws cellrt::Error("cancelled"). Null: never cancelled.
    const std::atomic<bool>* cancel = nullptr;
};

// valgrind's path if it is on PATH, else empty.
std::string find_valgrind();

// The folder callgrind's runs are made in: the system's temporary folder ($TMPDIR, $TMP, $TEMP or
// $TEMPDIR, else /tmp). Throws cellrt::Error naming the variable that chose it and its value when it
// is not a folder (the error was the standard library's "filesystem error: temp_directory_path: No
// such file or directory", after the work).
std::string temp_folder();

// Runs `command` (program and arguments; no shell) under callgrind and returns the events it
// collected. The program's own output is kept out of the way and shown only if it fails. Throws
// cellrt::Error when valgrind is missing, the run fails or its output cannot be read.
EventCounts run_callgrind(const std::vector<std::string>& command, const CallgrindOptions& options);

// The totals of a callgrind output file (events Ir, Bc, Bcm, Bi, Bim): instructions = Ir,
// branches = Bc + Bi, mispredictions = Bcm + Bim. `name` is the file's name in error messages.
EventCounts parse_callgrind_totals(std::istream& in, const std::string& name);

// Callgrind client requests, for a program run with instrument_at_start = false; no-ops when the
// program is not under valgrind. Unavailable (false) when built without valgrind's headers.
bool client_requests_available();
void start_instrumentation();
void stop_instrumentation();

}  // namespace cellrt::profile
