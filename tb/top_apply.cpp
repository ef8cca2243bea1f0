// top_apply.cpp: shades a list of gradients with the Verilated rmap_top and writes what the
// hardware outputs, one sample per clock, for `rmapgen render --rtl` and `rmapgen volume
// --rtl`. Unlike top_stream.cpp it knows no expected values: the caller compares.
//
//   top_apply INPUT_FILE OUTPUT_FILE      (run from the generated directory)
// INPUT_FILE: one sample per line, hex fields `gx gy gz` (G-bit two's complement) and, with
// colour, `r g b`. OUTPUT_FILE: one line per sample, in order, `zero i` and with colour
// `r_o g_o b_o`. Exits 1 if the pipeline loses, adds or delays a sample.
#include "Vrmap_top.h"
#include "rmap_top_config.h"
#include "verilated.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

static void die(const char* msg) {
    std::fprintf(stderr, "top_apply: %s\n", msg);
    std::exit(1);
}

int main(int argc, char** argv) {
    if (argc < 3) die("usage: top_apply INPUT_FILE OUTPUT_FILE");
    FILE* in = std::fopen(argv[1], "r");
    if (!in) die("cannot open the input file");
    std::vector<uint32_t> s;
    unsigned a, b, c, r = 0, g = 0, bl = 0;
    for (;;) {
#if RMAP_COLOR
        int n = std::fscanf(in, "%x %x %x %x %x %x", &a, &b, &c, &r, &g, &bl);
        if (n != 6) break;
#else
        int n = std::fscanf(in, "%x %x %x", &a, &b, &c);
        if (n != 3) break;
#endif
        s.insert(s.end(), {a, b, c, r, g, bl});
    }
    std::fclose(in);
    const size_t count = s.size() / 6;
    FILE* out = std::fopen(argv[2], "w");
    if (!out) die("cannot write the output file");

    auto ctx = std::make_unique<VerilatedContext>();
    auto top = std::make_unique<Vrmap_top>(ctx.get());
    auto tick = [&] {
        top->clk_i = 1;
        top->eval();
        top->clk_i = 0;
        top->eval();
    };
    top->clk_i = 0;
    top->rst_ni = 0;
    top->valid_i = 0;
    top->swap_i = 0;
    top->wr_en_i = 0;
#if RMAP_HANDSHAKE
    top->ready_i = 1;
#endif
    top->eval();
    tick();
    tick();
    top->rst_ni = 1;
    top->eval();

    size_t nin = 0, nout = 0;
    uint64_t clock = 0;
    while (nout < count) {
        if (top->valid_o) {
#if RMAP_COLOR
            std::fprintf(out, "%x %x %x %x %x\n", (unsigned)top->zero_o, (unsigned)top->i_o, (unsigned)top->r_o,
                         (unsigned)top->g_o, (unsigned)top->b_o);
#else
            std::fprintf(out, "%x %x\n", (unsigned)top->zero_o, (unsigned)top->i_o);
#endif
            ++nout;
        }
        top->valid_i = 0;
#if RMAP_HANDSHAKE
        const bool can_accept = top->ready_o;  // ready_i stays high: results leave at once
#else
        const bool can_accept = true;
#endif
        if (nin < count && can_accept) {
            const uint32_t* v = &s[6 * nin];
            top->valid_i = 1;
            top->gx_i = v[0];
            top->gy_i = v[1];
            top->gz_i = v[2];
#if RMAP_COLOR
            top->r_i = v[3];
            top->g_i = v[4];
            top->b_i = v[5];
#endif
            ++nin;
        }
        tick();
        if (++clock > count + 4 * RMAP_LATENCY + 64) die("the pipeline lost samples");
    }
    std::fclose(out);
    return 0;
}
