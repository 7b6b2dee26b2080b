#include "app/bench/machine.h"

#include <sched.h>
#include <sys/utsname.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <sstream>

#include "engine/util/format.h"

#ifndef LANCER_SOURCE_DIR
#define LANCER_SOURCE_DIR ""
#endif
#ifndef LANCER_VERSION
#define LANCER_VERSION "unknown"
#endif
#ifndef LANCER_BUILD_TYPE
#define LANCER_BUILD_TYPE ""
#endif

namespace lancer::bench {

namespace {

/// The value after "key :" on the first line of `path` that starts with `key`.
std::string field(const std::string& path, const std::string& key) {
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        if (line.compare(0, key.size(), key) != 0) continue;
        const size_t colon = line.find(':');
        if (colon == std::string::npos) continue;
        size_t b = line.find_first_not_of(" \t", colon + 1);
        return b == std::string::npos ? std::string() : line.substr(b);
    }
    return {};
}

}  // namespace

std::string shellQuote(const std::string& arg) {
    if (!arg.empty() &&
        arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                              "-_./:=+,@%") == std::string::npos)
        return arg;
    std::string out = "'";
    for (char c : arg) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::string peerExecutable(const char* envVar, const char* fallback) {
    const char* env = std::getenv(envVar);
    return env && *env ? env : fallback;
}

bool canRun(const std::string& executable) {
    bool ok = false;
    captureCommand("command -v " + shellQuote(executable), ok);
    return ok;
}

std::string readWholeFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string captureCommand(const std::string& command, bool& ok, bool keepStderr) {
    ok = false;
    FILE* p = ::popen((keepStderr ? command : "(" + command + ") 2>/dev/null").c_str(), "r");
    if (!p) return {};
    std::string out;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
    ok = ::pclose(p) == 0;
    return out;
}

RunInfo collectRunInfo(const std::vector<std::string>& argv) {
    RunInfo r;
    utsname u{};
    if (::uname(&u) == 0) r.system = std::string(u.sysname) + " " + u.release + " " + u.machine;
    r.cpu = field("/proc/cpuinfo", "model name");
    if (r.cpu.empty()) r.cpu = field("/proc/cpuinfo", "Model");
    if (r.cpu.empty()) r.cpu = u.machine;
    {
        std::ifstream in("/proc/cpuinfo");
        std::string line;
        while (std::getline(in, line))
            if (line.compare(0, 9, "processor") == 0) ++r.logicalCpus;
    }
    cpu_set_t set;
    CPU_ZERO(&set);
    if (::sched_getaffinity(0, sizeof set, &set) == 0) r.availableCpus = CPU_COUNT(&set);
    const std::string mem = field("/proc/meminfo", "MemTotal");  // "8143576 kB"
    if (!mem.empty()) {
        try {
            r.memory = formatBytes(size_t(std::stoull(mem)) * 1024);
        } catch (const std::exception&) {
            r.memory = mem;
        }
    }
    {
        std::ifstream in("/proc/loadavg");
        std::string a, b, c;
        if (in >> a >> b >> c) r.loadAverage = a + " " + b + " " + c;
    }
#if defined(__clang__)
    r.compiler = std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
    r.compiler = std::string("g++ ") + __VERSION__;
#endif
    if (*LANCER_BUILD_TYPE) r.compiler += std::string(", ") + LANCER_BUILD_TYPE;
    bool ok = false;
    std::string described;
    if (*LANCER_SOURCE_DIR)
        described = captureCommand(
            "git -C " + shellQuote(LANCER_SOURCE_DIR) + " describe --always --dirty --tags", ok);
    while (!described.empty() && (described.back() == '\n' || described.back() == '\r'))
        described.pop_back();
    r.commit = ok && !described.empty()
                   ? described + " (git describe of " + LANCER_SOURCE_DIR + ")"
                   : std::string("lancer ") + LANCER_VERSION + " (no git tree at the source path)";
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    ::gmtime_r(&now, &tm);
    char date[64];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S UTC", &tm);
    r.date = date;
    for (size_t i = 0; i < argv.size(); ++i) {
        if (i) r.command += ' ';
        r.command += shellQuote(argv[i]);
    }
    return r;
}

}  // namespace lancer::bench
