// prove_front.cpp: the front of the top (the modules that read the gradient: zero detect and
// sort & shift), Verilated inside the wrapper prove_front.v that `rmapgen prove` generates, as
// a shared object that rmapgen loads and drives (src/prove/ffi.rs). rmapgen chooses the
// inputs and compares with the model; this file only applies them, one per clock, and
// returns what the hardware outputs, in order.
#include "Vprove_front.h"
#include "verilated.h"

#include <cstddef>
#include <cstdint>

struct Front {
    VerilatedContext ctx;
    Vprove_front top{&ctx};
};

static void tick(Front* f) {
    f->top.clk_i = 1;
    f->top.eval();
    f->top.clk_i = 0;
    f->top.eval();
}

extern "C" {

// A model after reset.
void* rp_front_new() {
    auto* f = new Front;
    f->top.clk_i = 0;
    f->top.rst_ni = 0;
    f->top.valid_i = 0;
    f->top.eval();
    tick(f);
    f->top.rst_ni = 1;
    f->top.eval();
    return f;
}

void rp_front_free(void* h) { delete static_cast<Front*>(h); }

// Applies n gradients back to back (g[3k], g[3k+1], g[3k+2]: gx, gy, gz as G-bit fields),
// then flushes the pipeline. zero[k] and ss[k] receive the k-th output each module flagged
// valid. Returns 0, or -1 if a module delivered more or fewer than n outputs.
int rp_front_run(void* h, const uint16_t* g, size_t n, uint8_t* zero, uint64_t* ss) {
    auto* f = static_cast<Front*>(h);
    auto& t = f->top;
    size_t nz = 0, ns = 0;
    auto collect = [&] {
        if (t.zero_detect_valid_o) {
            if (nz == n) return false;
            zero[nz++] = t.zero_detect_o;
        }
        if (t.sort_shift_valid_o) {
            if (ns == n) return false;
            ss[ns++] = t.sort_shift_o;
        }
        return true;
    };
    for (size_t k = 0; k < n; ++k) {
        t.valid_i = 1;
        t.gx_i = g[3 * k];
        t.gy_i = g[3 * k + 1];
        t.gz_i = g[3 * k + 2];
        tick(f);
        if (!collect()) return -1;
    }
    t.valid_i = 0;
    // Drain: no module of the front is longer than 64 clocks.
    for (int c = 0; c < 64 && (nz < n || ns < n); ++c) {
        tick(f);
        if (!collect()) return -1;
    }
    return (nz == n && ns == n) ? 0 : -1;
}
}
