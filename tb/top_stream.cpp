// top_stream.cpp: streams a large vector file through the Verilated rmap_top, one sample per
// clock, and compares every output with the model's expectation.
//
// Built and run by `rmapgen sim --stream N` (src/sim/), which embeds this file; the Verilator
// command line is rmapgen::toolchain::verilator::harness:
//   verilator --cc --exe --build -O3 ... --top-module rmap_top <out>/*.v top_stream.cpp \
//             -CFLAGS "-O2 -I<out>/tb" --Mdir build/... -o top_stream
// Run as
//   top_stream VECTOR_FILE MAP2_X MAP2_Y MAP2_Z [MAP2_TABLE]
// with the design's second map files (<prefix>map2_<axis>.hex, and <prefix>map2_table.hex
// when the compensation table is a RAM, RMAP_TABLE_ENTRIES: written after the maps, axis slot
// 3, address u); the design's own $readmemh files are compiled in as absolute paths.
// VECTOR_FILE has the format of vectors/rmap_top.hex (`rmapgen vectors --count N` writes
// one): fields `map gx gy gz [r g b] zero i [r_o g_o b_o]`. While the map-0 vectors stream,
// the harness writes the second map MAP2_<AXIS> through the host port into the back buffer, one word
// per clock; the first map-1 vector waits for the load and is presented with swap_i high.
// Every output must appear in order, exactly RMAP_LATENCY clocks after its input. With the
// valid/ready handshake (RMAP_HANDSHAKE) the harness applies random backpressure (ready_i low
// one clock in four, and one clock in 256 a stall of up to 63 clocks), presents a sample only
// when ready_o is high, and takes a result with valid_o && ready_i; a result may then come
// later than RMAP_LATENCY clocks, never earlier, and exactly then when no backpressure came
// after its input. Prints the throughput, then `N passed, M failed` as the last line; exits 1
// on any failure.
#include "Vrmap_top.h"
#include "rmap_top_config.h"
#include "verilated.h"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace {

struct Vector {
    uint32_t line;
    uint8_t map;
    uint32_t g[3];
    uint8_t rgb[3];
    uint8_t zero;
    uint32_t i;
    uint8_t rgb_o[3];
};

#ifndef RMAP_TABLE_ENTRIES
#define RMAP_TABLE_ENTRIES 0
#endif
// The maps, then the table (its write k is axis 3, address k: the same split of the count).
constexpr uint32_t kWrites = (3u << RMAP_MAP_ADDR_BITS) + RMAP_TABLE_ENTRIES;
constexpr int kFiles = RMAP_TABLE_ENTRIES > 0 ? 4 : 3;
constexpr uint64_t kTimeout = 1000;
constexpr int kShow = 10;

[[noreturn]] void die(const std::string& msg) {
    std::printf("FATAL: %s\n", msg.c_str());
    std::fflush(stdout);
    std::exit(1);
}

std::string read_file(const std::string& path) {
    FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) die("cannot open " + path + " (run from the generated directory)");
    std::string s;
    char buf[1 << 16];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
    std::fclose(f);
    return s;
}

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// Parses the space-separated hex fields of one line; returns how many it read.
int parse_fields(const char*& p, const char* end, uint32_t* out, int max) {
    int n = 0;
    while (p < end && *p != '\n') {
        while (p < end && *p == ' ') ++p;
        if (p >= end || *p == '\n') break;
        uint32_t v = 0;
        int d, digits = 0;
        while (p < end && (d = hex_digit(*p)) >= 0) {
            v = v << 4 | static_cast<uint32_t>(d);
            ++p;
            ++digits;
        }
        if (digits == 0 || n == max) return -1;
        out[n++] = v;
    }
    if (p < end) ++p;  // the newline
    return n;
}

std::vector<Vector> load_vectors(const std::string& path) {
    const std::string text = read_file(path);
    std::vector<Vector> v;
    v.reserve(text.size() / 16);
    const char* p = text.data();
    const char* end = p + text.size();
    uint32_t f[RMAP_NFIELDS + 1];
    uint32_t line = 0;
    while (p < end) {
        ++line;
        const int n = parse_fields(p, end, f, RMAP_NFIELDS + 1);
        if (n == 0) continue;
        if (n != RMAP_NFIELDS) {
            die(path + " line " + std::to_string(line) + ": expected " + std::to_string(RMAP_NFIELDS) +
                " hex fields");
        }
        Vector x{};
        x.line = line;
        int k = 0;
        x.map = static_cast<uint8_t>(f[k++]);
        for (uint32_t& g : x.g) g = f[k++];
#if RMAP_COLOR
        for (uint8_t& c : x.rgb) c = static_cast<uint8_t>(f[k++]);
#endif
        x.zero = static_cast<uint8_t>(f[k++]);
        x.i = f[k++];
#if RMAP_COLOR
        for (uint8_t& c : x.rgb_o) c = static_cast<uint8_t>(f[k++]);
#endif
        v.push_back(x);
    }
    return v;
}

// The second map's files (x, y, z, and the table with RMAP_TABLE_ENTRIES): `//` comment
// lines, then one hex entry per line.
std::vector<uint32_t> load_map2(char** paths) {
    std::vector<uint32_t> m;
    for (int a = 0; a < kFiles; ++a) {
        const std::string path = paths[a];
        const std::string text = read_file(path);
        size_t before = m.size();
        size_t pos = 0;
        while (pos < text.size()) {
            size_t nl = text.find('\n', pos);
            if (nl == std::string::npos) nl = text.size();
            std::string line = text.substr(pos, nl - pos);
            pos = nl + 1;
            const size_t c = line.find("//");
            if (c != std::string::npos) line.resize(c);
            while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
            if (line.empty()) continue;
            uint32_t v = 0;
            for (char ch : line) {
                const int d = hex_digit(ch);
                if (d < 0) die(path + ": not a hex entry: " + line);
                v = v << 4 | static_cast<uint32_t>(d);
            }
            m.push_back(v);
        }
        const size_t want = a < 3 ? (1u << RMAP_MAP_ADDR_BITS) : RMAP_TABLE_ENTRIES;
        if (m.size() - before != want) die(path + ": wrong number of entries");
    }
    return m;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2 + kFiles) {
        std::fprintf(stderr, "usage: %s VECTOR_FILE MAP2_X MAP2_Y MAP2_Z%s\n", argv[0],
                     kFiles == 4 ? " MAP2_TABLE" : "");
        return 2;
    }
    const std::vector<Vector> vecs = load_vectors(argv[1]);
    const std::vector<uint32_t> map2 = load_map2(&argv[2]);
    const size_t n = vecs.size();
    if (n == 0) die(std::string(argv[1]) + " holds no vectors");

    auto ctx = std::make_unique<VerilatedContext>();
    ctx->commandArgs(argc, argv);
    auto top = std::make_unique<Vrmap_top>(ctx.get());

    uint64_t passed = 0, failed = 0, shown = 0;
    auto error = [&](const std::string& what) {
        ++failed;
        std::printf("ERROR: %s\n", what.c_str());
    };

    // The clock is low between ticks; a tick is one rising edge.
    top->clk_i = 0;
    top->rst_ni = 0;
    top->valid_i = 0;
    top->swap_i = 0;
    top->wr_en_i = 0;
#if RMAP_HANDSHAKE
    top->ready_i = 1;
    uint64_t rng = 0x9E3779B97F4A7C15ull;
    auto rnd = [&] {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        return rng;
    };
    int stall_left = 0;
    int64_t last_bp = -1;
#endif
    top->eval();
    auto tick = [&] {
        top->clk_i = 1;
        top->eval();
        top->clk_i = 0;
        top->eval();
    };
    for (int k = 0; k < 3; ++k) {
        tick();
        if (top->valid_o) error("valid_o in reset");
    }
    top->rst_ni = 1;
    top->eval();
    for (int k = 0; k < RMAP_LATENCY + 4; ++k) {
        tick();
        if (top->valid_o) error("valid_o before any input");
    }

    std::vector<uint64_t> accepted(n);
    size_t nin = 0, nout = 0;
    uint32_t nwr = 0;
    bool swapped = false;
    uint64_t clock = 0, last_progress = 0;
    const auto t0 = std::chrono::steady_clock::now();
    while (nout < n) {
#if RMAP_HANDSHAKE
        // Backpressure for the coming edge; a result leaves with valid_o && ready_i.
        bool ready = true;
        const uint64_t r = rnd();
        if (stall_left > 0) {
            ready = false;
            --stall_left;
        } else if (nin >= 64) {
            ready = (r & 3) != 0;
            if (((r >> 8) & 255) == 0) stall_left = static_cast<int>((r >> 16) & 63);
        }
        if (!ready) last_bp = static_cast<int64_t>(clock);
        top->ready_i = ready;
        const bool leaves = top->valid_o && ready;
#else
        const bool leaves = top->valid_o;
#endif
        // Outputs of the state after the last rising edge.
        if (leaves) {
            if (nout == nin) {
                error("valid_o with no sample in flight");
            } else {
                const Vector& e = vecs[nout];
                bool ok = top->zero_o == e.zero && top->i_o == e.i;
#if RMAP_COLOR
                ok = ok && top->r_o == e.rgb_o[0] && top->g_o == e.rgb_o[1] && top->b_o == e.rgb_o[2];
#endif
                const uint64_t lat = clock - accepted[nout];
#if RMAP_HANDSHAKE
                ok = ok && lat >= RMAP_LATENCY &&
                     (last_bp >= static_cast<int64_t>(accepted[nout]) || lat == RMAP_LATENCY);
#else
                ok = ok && lat == RMAP_LATENCY;
#endif
                if (ok) {
                    ++passed;
                } else {
                    ++failed;
                    if (shown++ < kShow) {
                        std::printf("MISMATCH line %u: in map=%x gx=%x gy=%x gz=%x", e.line, e.map, e.g[0], e.g[1],
                                    e.g[2]);
#if RMAP_COLOR
                        std::printf(" r=%x g=%x b=%x", e.rgb[0], e.rgb[1], e.rgb[2]);
#endif
                        std::printf("\n  expected zero=%x i=%x", e.zero, e.i);
#if RMAP_COLOR
                        std::printf(" r_o=%x g_o=%x b_o=%x", e.rgb_o[0], e.rgb_o[1], e.rgb_o[2]);
#endif
                        std::printf(" after %d clocks\n  got      zero=%x i=%x", RMAP_LATENCY,
                                    static_cast<unsigned>(top->zero_o), static_cast<unsigned>(top->i_o));
#if RMAP_COLOR
                        std::printf(" r_o=%x g_o=%x b_o=%x", static_cast<unsigned>(top->r_o),
                                    static_cast<unsigned>(top->g_o), static_cast<unsigned>(top->b_o));
#endif
                        std::printf(" after %llu clocks\n", static_cast<unsigned long long>(lat));
                    } else {
                        std::printf("MISMATCH line %u: expected zero=%x i=%x", e.line, e.zero, e.i);
#if RMAP_COLOR
                        std::printf(" r_o=%x g_o=%x b_o=%x", e.rgb_o[0], e.rgb_o[1], e.rgb_o[2]);
#endif
                        std::printf(", got zero=%x i=%x", static_cast<unsigned>(top->zero_o),
                                    static_cast<unsigned>(top->i_o));
#if RMAP_COLOR
                        std::printf(" r_o=%x g_o=%x b_o=%x", static_cast<unsigned>(top->r_o),
                                    static_cast<unsigned>(top->g_o), static_cast<unsigned>(top->b_o));
#endif
                        std::printf(" after %llu clocks\n", static_cast<unsigned long long>(lat));
                    }
                }
                ++nout;
                last_progress = clock;
            }
        }

        // The next sample, one per clock; the first map-1 sample waits for the map load.
        top->valid_i = 0;
        top->swap_i = 0;
        top->wr_en_i = 0;
#if RMAP_HANDSHAKE
        const bool can_accept = top->ready_o;
#else
        const bool can_accept = true;
#endif
        if (nin < n && can_accept) {
            const Vector& v = vecs[nin];
            if (!(v.map == 1 && !swapped && nwr < kWrites)) {
                if (v.map == 1 && !swapped) {
                    top->swap_i = 1;
                    swapped = true;
                } else if (v.map == 0 && swapped) {
                    die("line " + std::to_string(v.line) + ": a map-0 vector after the swap");
                }
                top->valid_i = 1;
                top->gx_i = v.g[0];
                top->gy_i = v.g[1];
                top->gz_i = v.g[2];
#if RMAP_COLOR
                top->r_i = v.rgb[0];
                top->g_i = v.rgb[1];
                top->b_i = v.rgb[2];
#endif
                accepted[nin++] = clock;
            }
        }
        // Host writes into the back buffer, never in the clock of the swap.
        if (nwr < kWrites && !top->swap_i) {
            top->wr_en_i = 1;
            top->wr_axis_i = nwr >> RMAP_MAP_ADDR_BITS;
            top->wr_addr_i = nwr & ((1u << RMAP_MAP_ADDR_BITS) - 1);
            top->wr_data_i = map2[nwr];
            ++nwr;
        }
        tick();
        ++clock;
        if (nout < nin && clock - last_progress > kTimeout) {
            die("timeout: no output for " + std::to_string(kTimeout) + " clocks, " + std::to_string(nout) +
                " checked");
        }
        if (nout == nin) last_progress = clock;
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    top->valid_i = 0;
    top->wr_en_i = 0;
    top->swap_i = 0;
#if RMAP_HANDSHAKE
    top->ready_i = 1;
#endif
    for (int k = 0; k < RMAP_LATENCY + 4; ++k) {
        tick();
        if (top->valid_o) error("valid_o after the last sample");
    }
    if (!swapped) error("no map-1 vector: the buffer swap was not tested");
    top->final();

    std::printf("rmap_top Verilator C++ harness: %zu vectors, %llu clocks in %.3f s: %.0f vectors/s\n", n,
                static_cast<unsigned long long>(clock), secs, static_cast<double>(n) / secs);
    std::printf("%llu passed, %llu failed\n", static_cast<unsigned long long>(passed),
                static_cast<unsigned long long>(failed));
    return failed == 0 && passed == n ? 0 : 1;
}
