{{ header }}
#include "{{ driver_h }}"

/* One value the identification check compares. */
struct {{ f }}id_field {
    uint32_t offset, mask, value;
};

/* Every constant of the identification block but rmapgen's own version, in register order;
 * ID and VERSION.REGMAP come first, so that a slave of another kind or version is named so. */
static const struct {{ f }}id_field {{ f }}id_fields[] = {
{%- for (r, fl) in checks %}
    { {{ p }}{{ r }}_OFFSET, {{ p }}{{ r }}_{{ fl }}_MASK, {{ p }}{{ r }}_{{ fl }}_VALUE << {{ p }}{{ r }}_{{ fl }}_SHIFT },
{%- endfor %}
};

int {{ f }}check(uintptr_t base, uint32_t *reg, uint32_t *got)
{
    size_t k;
    for (k = 0; k < sizeof {{ f }}id_fields / sizeof {{ f }}id_fields[0]; k++) {
        const struct {{ f }}id_field *c = &{{ f }}id_fields[k];
        uint32_t v = {{ p }}READ32(base, c->offset);
        if ((v & c->mask) != c->value) {
            if (reg) *reg = c->offset;
            if (got) *got = v;
            if (c->offset == {{ p }}ID_OFFSET) return {{ p }}ERR_ID;
            if (c->offset == {{ p }}VERSION_OFFSET) return {{ p }}ERR_REGMAP;
            return {{ p }}ERR_CONFIG;
        }
    }
    return {{ p }}OK;
}

/* The byte offset of a host write, or 0 when it is outside the windows (no window is at 0). */
static uint32_t {{ f }}entry(const uint16_t w[3])
{
    uint32_t axis = w[0], entry = w[1], data = w[2];
    if (axis <= 2u) {
        if (entry >= {{ p }}MAP_X_ENTRIES || data >> {{ p }}MAP_X_BITS != 0u) return 0u;
{%- if table %}
    } else if (axis == {{ p }}TABLE_AXIS) {
        if (entry >= {{ p }}TABLE_ENTRIES || data >> {{ p }}TABLE_BITS != 0u) return 0u;
{%- endif %}
    } else {
        return 0u;
    }
    return (uint32_t){{ p }}ENTRY_OFFSET(axis, entry);
}

int {{ f }}load(uintptr_t base, const uint16_t (*writes)[3], size_t count, size_t *bad)
{
    size_t k;
    for (k = 0; k < count; k++) {
        if ({{ f }}entry(writes[k]) == 0u) {
            if (bad) *bad = k;
            return {{ p }}ERR_WRITE;
        }
    }
    for (k = 0; k < count; k++) {
        {{ p }}WRITE32(base, {{ f }}entry(writes[k]), writes[k][2]);
    }
    return {{ p }}OK;
}

uint32_t {{ f }}frames(uintptr_t base)
{
    return {{ p }}READ32(base, {{ p }}FRAMES_OFFSET);
}

void {{ f }}request_swap(uintptr_t base)
{
    {{ p }}WRITE32(base, {{ p }}{{ swap_reg }}_OFFSET, {{ p }}{{ swap_reg }}_SWAP_MASK);
}

int {{ f }}wait_swap(uintptr_t base, uint32_t frames_before, unsigned long max_polls)
{
    unsigned long k;
    for (k = 0; k < max_polls; k++) {
        if ({{ f }}frames(base) != frames_before) return {{ p }}OK;
    }
    return {{ p }}ERR_TIMEOUT;
}

int {{ f }}swap(uintptr_t base, unsigned long max_polls)
{
    uint32_t before = {{ f }}frames(base);
    {{ f }}request_swap(base);
    return {{ f }}wait_swap(base, before, max_polls);
}

const char *{{ f }}strerror(int status)
{
    switch (status) {
    case {{ p }}OK: return "ok";
    case {{ p }}ERR_ID: return "no rmapgen slave at this address (ID is not RMAP)";
    case {{ p }}ERR_REGMAP: return "the slave has another register map version";
    case {{ p }}ERR_CONFIG: return "the slave is of another configuration than this driver";
    case {{ p }}ERR_WRITE: return "a map write outside this configuration's windows";
    case {{ p }}ERR_TIMEOUT: return "the swap did not happen in time";
    default: return "unknown status";
    }
}
