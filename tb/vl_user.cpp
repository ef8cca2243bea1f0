// vl_user.cpp: Verilator's $finish and $stop for the self-checking testbenches, compiled in
// with -CFLAGS -DVL_USER_FINISH -CFLAGS -DVL_USER_STOP (rmapgen::toolchain::verilator::binary,
// which embeds this file).
//
// The default $finish prints "- tb.v:N: Verilog $finish" after the testbench's verdict; this
// one prints nothing, so `N passed, M failed` stays the last line. The default $stop (and
// $fatal, which calls it) prints and aborts with 134; this one flushes and exits 1, the exit
// code vvp -N gives for the same testbench.
#include "verilated.h"

#include <cstdio>
#include <cstdlib>

void vl_finish(const char* /*filename*/, int /*linenum*/, const char* /*hier*/) {
    Verilated::threadContextp()->gotFinish(true);
}

void vl_stop(const char* /*filename*/, int /*linenum*/, const char* /*hier*/) {
    std::fflush(stdout);
    std::exit(1);
}
