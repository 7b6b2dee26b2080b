// What a report says of the run it measured: the machine (CPU, cores, memory, load), the source
// it was built from (git describe of the source tree, else the compiled-in version), the date and
// the command line, so a reader can tell one report's figures from another's.
#pragma once

#include <string>
#include <vector>

namespace lancer::bench {

struct RunInfo {
    std::string cpu;          ///< /proc/cpuinfo's model name (else the machine's architecture)
    int logicalCpus = 0;      ///< processors the kernel lists
    int availableCpus = 0;    ///< of them, those this process may run on (its affinity)
    std::string memory;       ///< /proc/meminfo's MemTotal, as "7.8 GiB"
    std::string loadAverage;  ///< /proc/loadavg's three averages at the start of the run
    std::string system;       ///< uname: "Linux 6.1.0 x86_64"
    std::string compiler;     ///< the compiler and build type of this executable
    std::string commit;   ///< `git describe --always --dirty` of the source tree, or the version
    std::string date;     ///< UTC, "2026-12-03 08:15:02 UTC"
    std::string command;  ///< the command line, each argument quoted as a shell needs it
};

/// The figures above, for a run started by `argv` (empty: no command line known).
RunInfo collectRunInfo(const std::vector<std::string>& argv);

/// `arg` as a POSIX shell reads it back: bare when it has only safe characters, else in single
/// quotes.
std::string shellQuote(const std::string& arg);

/// A peer's executable: $`envVar` when set and not empty, else `fallback` (found on the PATH).
std::string peerExecutable(const char* envVar, const char* fallback);
/// True when `executable` can be run (a path, or a name on the PATH).
bool canRun(const std::string& executable);
/// The whole of a file's bytes; empty when it cannot be read.
std::string readWholeFile(const std::string& path);

/// Run `command` with /bin/sh and return what it wrote on stdout (its stderr discarded unless
/// `keepStderr`); `ok` false when it could not be run or exited non-zero.
std::string captureCommand(const std::string& command, bool& ok, bool keepStderr = false);

}  // namespace lancer::bench
