{{ header }}
#ifndef {{ guard }}
#define {{ guard }}

/* The driver of the bus slave: check the identification block against the configuration
 * this file was generated for, load one frame's maps into the back buffer, swap, wait for
 * the swap. It keeps no state: every function takes the slave's base address.
 *
 * Register access: by default a volatile 32-bit load or store at base + offset (memory-
 * mapped I/O). Define {{ p }}READ32(base, offset) and {{ p }}WRITE32(base, offset, value)
 * before including this header to go through anything else (a simulator, a bus library). */

#include <stddef.h>
#include <stdint.h>

#include "{{ regs_h }}"

#ifndef {{ p }}READ32
#define {{ p }}READ32(base, offset) (*(volatile uint32_t *)((base) + (offset)))
#endif
#ifndef {{ p }}WRITE32
#define {{ p }}WRITE32(base, offset, value) (*(volatile uint32_t *)((base) + (offset)) = (uint32_t)(value))
#endif

/* What the functions return: 0, or one of these (negative). */
enum {
    {{ p }}OK = 0,
    {{ p }}ERR_ID = -1,       /* ID is not the magic value: no rmapgen slave at base */
    {{ p }}ERR_REGMAP = -2,   /* another register map version */
    {{ p }}ERR_CONFIG = -3,   /* another configuration (a layout field or the hash differs) */
    {{ p }}ERR_WRITE = -4,    /* a map write outside the windows of this configuration */
    {{ p }}ERR_TIMEOUT = -5   /* the swap did not happen within the polls allowed */
};

/* Checks the slave at base before anything is written to it: the magic, the register map's
 * version, every layout field and the configuration hash against this configuration's.
 * Returns {{ p }}OK or the first difference; *reg and *got (when not NULL) name the register
 * offset and the value read. */
int {{ f }}check(uintptr_t base, uint32_t *reg, uint32_t *got);

/* Writes count host writes {axis, address, data} (the array `rmapgen maps --format c`
 * writes) into the back buffer through the windows, in order. Every write is checked first;
 * one outside this configuration's windows writes nothing and returns {{ p }}ERR_WRITE with
 * its index in *bad (when not NULL). */
int {{ f }}load(uintptr_t base, const uint16_t (*writes)[3], size_t count, size_t *bad);

/* FRAMES: the swaps performed since reset. */
uint32_t {{ f }}frames(uintptr_t base);

/* Requests a swap (CONTROL.SWAP): it happens at the next frame boundary. */
void {{ f }}request_swap(uintptr_t base);

/* Waits until FRAMES differs from frames_before, reading it at most max_polls times. */
int {{ f }}wait_swap(uintptr_t base, uint32_t frames_before, unsigned long max_polls);

/* Requests a swap and waits for it: {{ f }}request_swap, then {{ f }}wait_swap. */
int {{ f }}swap(uintptr_t base, unsigned long max_polls);

/* A one-line description of a return value. */
const char *{{ f }}strerror(int status);

#endif /* {{ guard }} */
