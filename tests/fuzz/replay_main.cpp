// A libFuzzer stand-in for compilers without libFuzzer (the normal g++ test build): runs every
// file of a seed corpus through LLVMFuzzerTestOneInput, then deterministic mutations of them
// (byte flips, insertions of format tokens, deletions, duplications, splices). A crash fails
// the test; so does an input that takes longer than a second (a hang in the making).
//
//   fuzz_replay_nff CORPUS_DIR [MUTATIONS_PER_FILE] [SEED]
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

// Tokens of both formats, so mutations reach deeper than random bytes would.
const char* kDictionary[] = {
    " ", "\n", "\t", "0", "-1", "1e308", "1e999", "nan", "inf", "-inf", "0.5", "99999999999", "#",
    "v\n", "from", "at", "up", "angle", "hither", "resolution", "b", "l", "f", "s", "p", "pp", "c",
    "{", "}", "(", ")", "[", "]", ",", ";", "=", "%", "*", "!", "\"", "//", "/*", "*/", "group()",
    "union()", "difference()", "intersection()", "render()", "color(\"red\")",
    "multmatrix([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])", "cube(1);",
    "sphere(r = 1);", "cylinder(h = 1, r1 = 1, r2 = 0);", "center = true", "$fn = 0", "undef",
    "hull()", "[[", "]]",
    // OpenSCAD's 2D nodes and extrusions (the pipeline's .csg inputs)
    "linear_extrude(height = 1, twist = 90, slices = 2)", "rotate_extrude(angle = 180)",
    "circle(r = 1);", "square(size = [2, 1], center = true);",
    "polygon(points = [[0, 0], [1, 0], [0, 1]]);", "offset(r = 0.5)",
    // DXF group codes and entities
    "\n0\n", "\n8\n", "\n10\n", "\n20\n", "\n40\n", "\n42\n", "\n50\n", "\n70\n", "LINE", "ARC",
    "CIRCLE", "LWPOLYLINE", "POLYLINE", "VERTEX", "INSERT", "BLOCK", "ENDBLK", "SECTION", "ENDSEC"};

bool run(const std::string& input, const std::string& what) {
    // LANCER_FUZZ_LAST=FILE keeps each input there before it runs: after a crash, the input that
    // crashed (libFuzzer writes its own crash-* files; this driver has no other record).
    static const char* last = std::getenv("LANCER_FUZZ_LAST");
    if (last) std::ofstream(last, std::ios::binary) << input;
    auto start = std::chrono::steady_clock::now();
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(input.data()), input.size());
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (s > 1.0) {
        std::fprintf(stderr, "FAIL: %s took %.2f s (%zu bytes)\n", what.c_str(), s, input.size());
        std::ofstream("fuzz-slow-input", std::ios::binary) << input;
        return false;
    }
    return true;
}

std::string mutate(const std::string& in, const std::vector<std::string>& corpus,
                   std::mt19937_64& rng) {
    std::string s = in;
    int steps = 1 + int(rng() % 4);
    for (int k = 0; k < steps; ++k) {
        size_t n = s.size();
        size_t at = n ? rng() % (n + 1) : 0;
        switch (rng() % 6) {
            case 0:  // flip a byte
                if (n) s[rng() % n] = char(rng() % 256);
                break;
            case 1:  // insert a token
                s.insert(at, kDictionary[rng() % (sizeof kDictionary / sizeof *kDictionary)]);
                break;
            case 2:  // delete a range
                if (n) s.erase(at < n ? at : n - 1, 1 + rng() % 16);
                break;
            case 3:  // duplicate a range
                if (n) {
                    size_t from = rng() % n, len = 1 + rng() % 64;
                    s.insert(at, s.substr(from, len));
                }
                break;
            case 4:  // splice another corpus file
                if (!corpus.empty()) {
                    const std::string& o = corpus[rng() % corpus.size()];
                    size_t from = o.empty() ? 0 : rng() % o.size();
                    s.insert(at, o.substr(from, 1 + rng() % 256));
                }
                break;
            default:  // truncate
                s.resize(at);
                break;
        }
    }
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s CORPUS_DIR [MUTATIONS_PER_FILE] [SEED]\n", argv[0]);
        return 2;
    }
    long mutations = argc > 2 ? std::stol(argv[2]) : 1000;
    uint64_t seed = argc > 3 ? std::stoull(argv[3]) : 1;
    std::vector<std::string> corpus, names;
    for (const auto& e : std::filesystem::directory_iterator(argv[1])) {
        if (!e.is_regular_file()) continue;
        std::ifstream f(e.path(), std::ios::binary);
        std::ostringstream ss;
        ss << f.rdbuf();
        corpus.push_back(ss.str());
        names.push_back(e.path().filename().string());
    }
    if (corpus.empty()) {
        std::fprintf(stderr, "FAIL: no seed files in %s\n", argv[1]);
        return 1;
    }
    std::mt19937_64 rng(seed);
    long runs = 0;
    for (size_t i = 0; i < corpus.size(); ++i) {
        if (!run(corpus[i], names[i])) return 1;
        ++runs;
        for (long m = 0; m < mutations; ++m, ++runs)
            if (!run(mutate(corpus[i], corpus, rng), names[i] + " mutation " + std::to_string(m)))
                return 1;
    }
    std::printf("PASS: %ld inputs from %zu seeds, no crash, none slower than 1 s\n", runs,
                corpus.size());
    return 0;
}
