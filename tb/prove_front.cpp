// prove_front.cpp: the front of the top (the modules that read the gradient: zero detect and
// sort & shift), Verilated inside the wrapper prove_front.v that `rmapgen prove` generates
// (RP_LANES copies side by side, ports named in prove_front_lanes.h), as a shared object that
// rmapgen loads and drives (src/prove/ffi.rs). rmapgen chooses the inputs and compares with
// the model; this file only applies them, RP_LANES per clock, and returns what the hardware
// outputs, in order.
#include "Vprove_front.h"
#include "prove_front_lanes.h"
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

// The number of gradients applied per clock; rp_front_run takes a multiple of it.
size_t rp_front_lanes() { return RP_LANES; }

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

// Applies n gradients (n a multiple of RP_LANES; g[3k], g[3k+1], g[3k+2]: gx, gy, gz as
// G-bit fields), RP_LANES per clock back to back, then flushes the pipeline. zero[k] and
// ss[k] receive the k-th result of each module, in order. Returns 0, or -1 if n is not a
// multiple of RP_LANES or a module delivered more or fewer than n results.
int rp_front_run(void* h, const uint16_t* g, size_t n, uint8_t* zero, uint64_t* ss) {
    auto* f = static_cast<Front*>(h);
    auto& t = f->top;
    if (n % RP_LANES != 0) return -1;
    size_t nz = 0, ns = 0;
    auto collect = [&] {
        if (RP_ZERO_VALID(t)) {
            if (nz == n) return false;
            RP_ZEROS(t, (zero + nz));
            nz += RP_LANES;
        }
        if (RP_SORT_VALID(t)) {
            if (ns == n) return false;
            RP_SORTS(t, (ss + ns));
            ns += RP_LANES;
        }
        return true;
    };
    for (size_t k = 0; k < n; k += RP_LANES) {
        t.valid_i = 1;
        const uint16_t* p = g + 3 * k;
        RP_APPLY(t, p);
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
