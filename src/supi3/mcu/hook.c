/* The emulated core's block hook and empty memory hook in native code (MCU-25; docs/assumptions/mcu.md).
 *
 * Built for the host on first use by supi3.mcu.hook (the Zig toolchain from PyPI) and loaded with ctypes. It links
 * against nothing: unicorn's functions it calls come as pointers in the shared state, which the Python side
 * (supi3.mcu.core.CortexM) owns and reads between runs and in its peripheral callbacks.
 *
 * The block hook does what MCU-1, MCU-10 and MCU-11 say, to the cycle:
 *   - refuse the block (uc_emu_stop) on a stop request or at the deadline: it is the first of the next run;
 *   - otherwise take its cost (instructions, cycles) from a cache filled by Python's block_cost; a block not in the
 *     cache calls Python's `describe` once, which fills the cache and `fresh`; a block in RAM calls it each time it
 *     runs (MCU-28: the firmware may have rewritten it);
 *   - a poll loop whose status was just read (skip_address) counts its iterations up to the status change or the
 *     deadline without running them (MCU-10); a countdown block (SUBS Rd, Rd, #1; BNE) counts all but its last
 *     iteration up to the deadline and writes Rd back (MCU-11);
 *   - note the block's address, entry cycle and end (a peripheral access is timed inside its block by the PC).
 *
 * A peripheral's reads go first to supi3_held_read: a register whose value the peripheral holds until a cycle (SPI1's
 * SR while a byte shifts) is answered here, as the peripheral would answer it, and so is one read of a register the
 * peripheral offers from a cycle on (SPI1's DR once its byte has ended, MCU-26); every other read goes to Python.
 */
#include <stddef.h>
#include <stdint.h>

typedef struct {
    uint32_t address;
    uint32_t size; /* 0: an empty slot */
    uint32_t instructions;
    uint32_t cycles;
    int32_t countdown; /* the register a countdown loop counts down (0 to 7), or -1 */
    int32_t poll;      /* a pure poll loop (MCU-10) */
} supi3_block;

typedef int (*uc_emu_stop_fn)(void *uc);
typedef int (*uc_reg_fn)(void *uc, int regid, void *value);
typedef int (*describe_fn)(uint64_t address, uint32_t size);
typedef uint64_t (*mmio_read_fn)(void *uc, uint64_t offset, unsigned size, void *data);

typedef struct {
    uint64_t cycles;
    uint64_t instructions;
    uint64_t deadline;
    uint64_t block_start;   /* cycle at the entry of the block running */
    uint64_t block_address;
    uint64_t block_end;
    uint64_t skip_until;    /* MCU-10: the cycle the polled status changes */
    uint64_t skip_address;  /* MCU-10: the poll loop's address */
    uint64_t handed;        /* the latest time a peripheral was given (CortexM.cycles_polled) */
    uint32_t skip_pending;  /* a status read asked for a skip at the next block */
    uint32_t stop_request;
    uint32_t skip_polls;    /* MCU-10 and MCU-11 on */
    uint32_t mask;          /* cache slots - 1 (a power of two) */
    uint32_t block_poll;    /* the block running is a pure poll loop (MCU-10) */
    supi3_block *cache;
    supi3_block fresh;      /* `describe` writes the block's cost here */
    uint64_t access_pc;     /* the PC of the latest peripheral access */
    int32_t low_registers[8]; /* unicorn's numbers of R0..R7 */
    int32_t pc_register;    /* unicorn's number of the PC */
    uc_emu_stop_fn emu_stop;
    uc_reg_fn reg_read;
    uc_reg_fn reg_write;
    describe_fn describe;   /* nonzero: Python failed, stop */
    uint64_t rewritable;    /* MCU-28: blocks from this address (the RAM's base) ... */
    uint64_t rewritable_size; /* ... up to this many bytes on are never taken from the cache: `describe` each run */
    uint32_t code_written;  /* MCU-28: the firmware stored into flash: CortexM forgets every cost of code */
} supi3_state;

/* MCU-28: the cycles up to the deadline as a signed count: a deadline in the past is none, and one more than 2^63 - 1
 * cycles away (CortexM keeps deadlines to MAX_DEADLINE, but the state is written from outside) is 2^63 - 1: the
 * unsigned difference never turns negative and stops the skips. */
static int64_t until_deadline(const supi3_state *s) {
    if (s->cycles >= s->deadline) {
        return 0;
    }
    uint64_t left = s->deadline - s->cycles;
    return left > (uint64_t)INT64_MAX ? INT64_MAX : (int64_t)left;
}

static int64_t ceil_div(int64_t numerator, int64_t denominator) {
    /* denominator > 0; C division truncates toward zero, which is the ceiling for a negative numerator; no sum that
     * could pass INT64_MAX (MCU-28) */
    return numerator / denominator + (numerator > 0 && numerator % denominator != 0);
}

static int64_t at_least_zero(int64_t value) { return value > 0 ? value : 0; }

static int64_t smaller(int64_t a, int64_t b) { return a < b ? a : b; }

static void skip_polls(supi3_state *s, const supi3_block *cost, uint64_t until) {
    int64_t cycles = cost->cycles;
    int64_t before_deadline = ceil_div(until_deadline(s), cycles);
    int64_t reading_early = ceil_div((int64_t)until - cycles - (int64_t)s->cycles, cycles);
    int64_t skipped = at_least_zero(smaller(before_deadline, reading_early));
    s->instructions += (uint64_t)skipped * cost->instructions;
    s->cycles += (uint64_t)skipped * cost->cycles;
}

/* Whether the deadline came first: the block must not run. */
static int skip_countdown(supi3_state *s, void *uc, const supi3_block *cost) {
    int regid = s->low_registers[cost->countdown];
    uint64_t left = 0;
    s->reg_read(uc, regid, &left);
    left &= 0xFFFFFFFFu;
    int64_t skipped = at_least_zero(smaller((int64_t)left - 1, ceil_div(until_deadline(s), cost->cycles)));
    if (skipped) {
        uint64_t value = left - (uint64_t)skipped;
        s->reg_write(uc, regid, &value);
        s->instructions += (uint64_t)skipped * cost->instructions;
        s->cycles += (uint64_t)skipped * cost->cycles;
    }
    return s->cycles >= s->deadline;
}

void supi3_block_hook(void *uc, uint64_t address, uint32_t size, void *data) {
    supi3_state *s = (supi3_state *)data;
    if (s->stop_request || s->cycles >= s->deadline) {
        s->emu_stop(uc); /* this block does not run: it is the first of the next run */
        return;
    }
    const supi3_block *cost = &s->cache[(address >> 1) & s->mask];
    if (cost->size != size || cost->address != address || size == 0
        || address - s->rewritable < s->rewritable_size) { /* MCU-28: code in RAM may have been rewritten */
        if (s->describe(address, size)) {
            s->emu_stop(uc);
            return;
        }
        cost = &s->fresh;
    }
    if (s->skip_pending) {
        s->skip_pending = 0;
        if (s->skip_address == address && cost->cycles) { /* the poll loop again (never a block of no code) */
            skip_polls(s, cost, s->skip_until);
            if (s->cycles >= s->deadline) {
                s->emu_stop(uc);
                return;
            }
        }
    }
    if (cost->countdown >= 0 && s->skip_polls && skip_countdown(s, uc, cost)) {
        s->emu_stop(uc);
        return;
    }
    s->block_address = address;
    s->block_start = s->cycles;
    s->block_end = address + size;
    s->block_poll = (uint32_t)cost->poll;
    s->instructions += cost->instructions;
    s->cycles += cost->cycles;
}

/* The memory hook of each peripheral range: its presence makes unicorn keep the PC exact at each access it covers
 * (MCU-1); it notes that PC for the peripheral's callback, which runs next (CortexM.cycles_now). */
void supi3_exact_pc(void *uc, int type, uint64_t address, int size, int64_t value, void *data) {
    supi3_state *s = (supi3_state *)data;
    (void)type;
    (void)address;
    (void)size;
    (void)value;
    s->access_pc = 0;
    s->reg_read(uc, s->pc_register, &s->access_pc);
}

/* MCU-28: the memory hook of flash (uc_cb_hookmem_t). A store there may change code whose cost the cache holds: the
 * run stops at the end of the block and CortexM forgets every cost of code before the next. */
void supi3_code_written(void *uc, int type, uint64_t address, int size, int64_t value, void *data) {
    supi3_state *s = (supi3_state *)data;
    (void)uc;
    (void)type;
    (void)address;
    (void)size;
    (void)value;
    s->code_written = 1;
    s->stop_request = 1;
}

/* A register value a peripheral holds while the read's time is before `until` (MCU-25). */
typedef struct {
    supi3_state *state;
    mmio_read_fn slow; /* the peripheral's read in Python */
    uint64_t until;
    uint32_t offset;
    uint32_t value;
    uint32_t held;     /* a value is held */
    uint32_t poll;     /* a read tells the poll skip (MCU-10) the cycle `until`, the status's change */
    uint32_t after;    /* the value from `until` on, if has_after */
    uint32_t has_after;
    uint64_t once_from; /* MCU-26: one read of once_offset at or after this cycle returns once_value */
    uint64_t once_at;   /* the time of that read, once taken */
    uint32_t once_offset;
    uint32_t once_value;
    uint32_t once;      /* offered, not yet taken */
    uint32_t taken;     /* taken: the held register reads once_then from now on */
    uint32_t once_then;
} supi3_held;

/* A peripheral's read callback (uc_cb_mmio_read_t): the offered register's one read from `once_from` on (MCU-26);
 * the held register as CortexM.cycles_polled and CortexM.skip_poll would do it (once the offered read was taken:
 * `once_then`; before `until`: the value and the poll skip; from then on: `after`, no skip), or Python's read. A
 * stop request (a failure, or a change the run loop must see) always goes to Python. */
uint64_t supi3_held_read(void *uc, uint64_t offset, unsigned size, void *data) {
    supi3_held *h = (supi3_held *)data;
    supi3_state *s = h->state;
    if (h->once && offset == h->once_offset && !s->stop_request) { /* MCU-26 */
        uint64_t time = s->handed > s->cycles ? s->handed : s->cycles;
        if (time >= h->once_from) {
            s->handed = time;
            h->once = 0;
            h->taken = 1;
            h->once_at = time;
            return h->once_value;
        }
    }
    if (h->held && offset == h->offset && !s->stop_request) {
        uint64_t time = s->handed > s->cycles ? s->handed : s->cycles;
        if (h->taken) { /* the offered read was taken: the value after it, until the peripheral's next access */
            s->handed = time;
            return h->once_then;
        }
        if (time < h->until) {
            s->handed = time;
            if (h->poll && s->skip_polls && s->block_poll) {
                s->skip_address = s->block_address;
                s->skip_until = h->until;
                s->skip_pending = 1;
            }
            return h->value;
        }
        if (h->has_after) {
            s->handed = time;
            return h->after;
        }
    }
    return h->slow(uc, offset, size, 0);
}

/* The layout of the structs above as this compiler lays them out: the number of values after it, the struct's size, then each
 * field's offset in the order of its declaration. supi3.mcu.hook checks its ctypes mirrors against them when it loads
 * the library (MCU-25): a mismatch is a NativeHookError, not memory written at the wrong place. */
#define AT(type, field) (uint32_t) offsetof(type, field)
const uint32_t supi3_block_layout[] = {7, sizeof(supi3_block), AT(supi3_block, address), AT(supi3_block, size),
                                       AT(supi3_block, instructions), AT(supi3_block, cycles),
                                       AT(supi3_block, countdown), AT(supi3_block, poll)};
const uint32_t supi3_state_layout[] = {
    27, sizeof(supi3_state), AT(supi3_state, cycles), AT(supi3_state, instructions), AT(supi3_state, deadline),
    AT(supi3_state, block_start), AT(supi3_state, block_address), AT(supi3_state, block_end),
    AT(supi3_state, skip_until), AT(supi3_state, skip_address), AT(supi3_state, handed),
    AT(supi3_state, skip_pending), AT(supi3_state, stop_request), AT(supi3_state, skip_polls), AT(supi3_state, mask),
    AT(supi3_state, block_poll), AT(supi3_state, cache), AT(supi3_state, fresh), AT(supi3_state, access_pc),
    AT(supi3_state, low_registers), AT(supi3_state, pc_register), AT(supi3_state, emu_stop),
    AT(supi3_state, reg_read), AT(supi3_state, reg_write), AT(supi3_state, describe), AT(supi3_state, rewritable),
    AT(supi3_state, rewritable_size), AT(supi3_state, code_written)};
const uint32_t supi3_held_layout[] = {
    17, sizeof(supi3_held), AT(supi3_held, state), AT(supi3_held, slow), AT(supi3_held, until), AT(supi3_held, offset),
    AT(supi3_held, value), AT(supi3_held, held), AT(supi3_held, poll), AT(supi3_held, after),
    AT(supi3_held, has_after), AT(supi3_held, once_from), AT(supi3_held, once_at), AT(supi3_held, once_offset),
    AT(supi3_held, once_value), AT(supi3_held, once), AT(supi3_held, taken), AT(supi3_held, once_then)};
