// prove_top.cpp: the design's top (rmap_top), Verilated as a shared object that `rmapgen
// prove` loads and drives (src/prove/ffi.rs). rmapgen chooses the gradients and compares with
// the model; this file only applies them, one per clock with ready_i high, and returns what
// the hardware outputs, in order.
#include "Vrmap_top.h"
#include "rmap_top_config.h"
#include "verilated.h"

#include <cstddef>
#include <cstdint>

struct Top {
    VerilatedContext ctx;
    Vrmap_top top{&ctx};
};

static void tick(Top* d) {
    d->top.clk_i = 1;
    d->top.eval();
    d->top.clk_i = 0;
    d->top.eval();
}

extern "C" {

// A model after reset, the front map buffer the one its init files load.
void* rp_top_new() {
    auto* d = new Top;
    auto& t = d->top;
    t.clk_i = 0;
    t.rst_ni = 0;
    t.valid_i = 0;
    t.swap_i = 0;
    t.wr_en_i = 0;
#if RMAP_HANDSHAKE
    t.ready_i = 1;
#endif
    t.eval();
    tick(d);
    tick(d);
    t.rst_ni = 1;
    t.eval();
    return d;
}

void rp_top_free(void* h) { delete static_cast<Top*>(h); }

// Host writes into the back map buffer, one per clock with no sample: w[3k..3k+3] is the
// k-th write's axis, address and data. Returns the number of writes applied.
size_t rp_top_write(void* h, const uint32_t* w, size_t n) {
    auto* d = static_cast<Top*>(h);
    auto& t = d->top;
    t.valid_i = 0;
    t.swap_i = 0;
    for (size_t k = 0; k < n; ++k) {
        t.wr_en_i = 1;
        t.wr_axis_i = w[3 * k];
        t.wr_addr_i = w[3 * k + 1];
        t.wr_data_i = w[3 * k + 2];
        tick(d);
    }
    t.wr_en_i = 0;
    tick(d);
    return n;
}

// Exchanges the front and back map buffers: swap_i high for one clock with no sample (the
// pipeline is empty: rp_top_run returns only when every result has left).
void rp_top_swap(void* h) {
    auto* d = static_cast<Top*>(h);
    auto& t = d->top;
    t.valid_i = 0;
    t.wr_en_i = 0;
    t.swap_i = 1;
    tick(d);
    t.swap_i = 0;
    tick(d);
}

// Applies n samples back to back (in[6k..6k+6]: gx gy gz as G-bit fields, then r g b, used
// with colour) and flushes. out[5k..5k+5] receives the k-th result: zero, i, r, g, b (the
// colour 0 without colour). Returns the number of results collected (n), or -1 if the
// pipeline lost or added a sample.
long rp_top_run(void* h, const uint32_t* in, size_t n, uint32_t* out) {
    auto* d = static_cast<Top*>(h);
    auto& t = d->top;
    size_t nin = 0, nout = 0;
    uint64_t clock = 0;
    while (nout < n) {
        if (t.valid_o) {
            uint32_t* o = &out[5 * nout];
            o[0] = t.zero_o;
            o[1] = t.i_o;
#if RMAP_COLOR
            o[2] = t.r_o;
            o[3] = t.g_o;
            o[4] = t.b_o;
#else
            o[2] = o[3] = o[4] = 0;
#endif
            ++nout;
        }
        t.valid_i = 0;
#if RMAP_HANDSHAKE
        const bool can_accept = t.ready_o;  // ready_i stays high: nothing waits
#else
        const bool can_accept = true;
#endif
        if (nin < n && can_accept) {
            const uint32_t* v = &in[6 * nin];
            t.valid_i = 1;
            t.gx_i = v[0];
            t.gy_i = v[1];
            t.gz_i = v[2];
#if RMAP_COLOR
            t.r_i = v[3];
            t.g_i = v[4];
            t.b_i = v[5];
#endif
            ++nin;
        }
        tick(d);
        if (++clock > n + 4 * RMAP_LATENCY + 64) return -1;
    }
    // One clock more: a sample beyond n would show here.
    if (t.valid_o) return -1;
    return static_cast<long>(nout);
}
}
