/* The emulated core's block hook, exact-PC hook and virtual TLB in native code (MCU-25, MCU-89; docs/assumptions/mcu.md).
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
 *
 * The exception entry's, tail-chain's and return's register and memory traffic, a run's start and the interrupt hook
 * are here too (MCU-70 to MCU-72): CortexM keeps every decision and report and calls them once each.
 */
#include <stdbool.h>
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
typedef int (*uc_mem_fn)(void *uc, uint64_t address, void *bytes, uint64_t size); /* uc_mem_read, uc_mem_write */
typedef int (*uc_emu_start_fn)(void *uc, uint64_t begin, uint64_t until, uint64_t timeout, uint64_t count);

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
    /* MCU-70 to MCU-72: the exception entry's and return's register and memory traffic (B1.5.6, B1.5.8) and the run's
     * start, done here; unicorn's functions and numbers and the architecture's constants handed over by CortexM */
    uc_mem_fn mem_read;
    uc_mem_fn mem_write;
    uc_emu_start_fn emu_start;
    int32_t exc_registers[11]; /* unicorn's numbers of CONTROL, SP, R0-R3, R12, LR, xPSR, PC, PSP */
    uint32_t exc_return_handler, exc_return_thread_msp, exc_return_thread_psp;
    uint32_t xpsr_t, xpsr_align, control_spsel;
    uint32_t interrupt;     /* the CPU exception unicorn raised in the last run (supi3_interrupt), or no_interrupt */
    uint32_t no_interrupt;
    int64_t frame;          /* the frame an entry stacked (or failed to), an unstacking failed at */
    uint64_t vector;        /* the vector an entry or a tail-chain read */
    uint64_t pc;            /* the PC after supi3_run */
    int32_t status;         /* unicorn's error of a failed stacking */
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

/* The protection hook of each run of adjacent peripheral ranges (uc_cb_eventmem_t; MCU-89: the ranges are mapped
 * inaccessible, so each load and store of them calls it, and unicorn restores the PC before it, MCU-1): it notes that
 * PC for the peripheral's callback, which runs next (CortexM.cycles_now), and lets the access go on. */
bool supi3_exact_pc(void *uc, int type, uint64_t address, int size, int64_t value, void *data) {
    supi3_state *s = (supi3_state *)data;
    (void)type;
    (void)address;
    (void)size;
    (void)value;
    s->access_pc = 0;
    s->reg_read(uc, s->pc_register, &s->access_pc);
    return true;
}

/* MCU-89: the virtual TLB (uc_tlb_entry, uc_cb_tlbevent_t). Each address is itself; a page is readable, writable and
 * executable as the default memory map has it (ARMv7-M B3.1, Table B3-1: its Execute Never regions from CortexM);
 * flash is writable only for a store's fill, which notes the store as MCU-28 needs (CortexM forgets every cost of
 * code after the run and empties the TLB, so that the next store fills again). A fetch refused ends the run with
 * unicorn's UC_ERR_EXCEPTION: `prefetch_abort` in `interrupt` says it was this one (QEMU raised it as
 * EXCP_PREFETCH_ABORT before the virtual TLB). */
typedef struct {
    uint64_t paddr;
    int32_t perms;
} supi3_tlb_entry;

typedef struct {
    supi3_state *state;
    uint64_t flash;
    uint64_t flash_size;
    uint64_t never_low[2];  /* the Execute Never regions, [low, high) */
    uint64_t never_high[2];
    int32_t fetch;          /* unicorn's UC_MEM_FETCH and UC_MEM_WRITE */
    int32_t store;
    int32_t prot_write;     /* unicorn's UC_PROT_WRITE, UC_PROT_EXEC, UC_PROT_ALL */
    int32_t prot_exec;
    int32_t prot_all;
    uint32_t prefetch_abort;
} supi3_memory;

bool supi3_tlb_fill(void *uc, uint64_t address, int type, supi3_tlb_entry *entry, void *data) {
    supi3_memory *m = (supi3_memory *)data;
    supi3_state *s = m->state;
    (void)uc;
    entry->paddr = address;
    entry->perms = m->prot_all;
    for (int k = 0; k < 2; k++) {
        if (address - m->never_low[k] < m->never_high[k] - m->never_low[k]) {
            entry->perms &= ~m->prot_exec;
            if (type == m->fetch) {
                s->interrupt = m->prefetch_abort;
            }
        }
    }
    if (address - m->flash < m->flash_size) {
        if (type == m->store) { /* MCU-28: a store into flash may change code whose cost the cache holds */
            s->code_written = 1;
            s->stop_request = 1;
        } else {
            entry->perms &= ~m->prot_write;
        }
    }
    return true;
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

/* MCU-70 to MCU-72: CortexM's exception entry and return (B1.5.6, B1.5.8) and the start of a run, without a register
 * or memory access of its own through ctypes. CortexM decides what to take and when, keeps the active and pending
 * exceptions, the cycles and every fault report; these only move the registers and the frame, each step as its Python
 * path does it (CortexM.native_exceptions = False), in the same order. */
enum { EXC_CONTROL, EXC_SP, EXC_R0, EXC_LR = EXC_R0 + 5, EXC_XPSR, EXC_PC, EXC_PSP };
enum { FRAME_WORDS = 8 }; /* the basic frame: R0-R3, R12, LR, the return address, xPSR, in address order */

static uint32_t core_read(void *uc, const supi3_state *s, int index) {
    uint64_t value = 0;
    s->reg_read(uc, s->exc_registers[index], &value);
    return (uint32_t)value;
}

static void core_write(void *uc, const supi3_state *s, int index, uint32_t value) {
    uint64_t wide = value;
    s->reg_write(uc, s->exc_registers[index], &wide);
}

static uint32_t little_endian(const uint8_t *bytes) {
    return (uint32_t)bytes[0] | (uint32_t)bytes[1] << 8 | (uint32_t)bytes[2] << 16 | (uint32_t)bytes[3] << 24;
}

/* CortexM._take's traffic (also a tail-chain's): LR = exc_return, xPSR = T | number, PC = the vector read at
 * vector_address, bit 0 cleared (`vector`: as read). 1 if the vector is not in memory (LR and xPSR written, as the
 * Python path leaves them for its report). */
int supi3_take(void *uc, supi3_state *s, uint32_t number, uint32_t exc_return, uint64_t vector_address) {
    uint8_t bytes[4];
    core_write(uc, s, EXC_LR, exc_return);
    core_write(uc, s, EXC_XPSR, s->xpsr_t | number);
    if (s->mem_read(uc, vector_address, bytes, sizeof bytes) != 0) {
        return 1;
    }
    s->vector = little_endian(bytes);
    core_write(uc, s, EXC_PC, (uint32_t)s->vector & ~1u);
    return 0;
}

/* CortexM.enter's traffic: the basic frame stacked on the current stack (the process stack in thread mode with
 * CONTROL.SPSEL set), aligned to 8 bytes with xPSR bit 9 (B1.5.7), SP = the frame (`frame`), SPSEL cleared, then
 * supi3_take with the EXC_RETURN of the mode. 1: the frame is not in memory (nothing written; `status`: unicorn's
 * error); 2: the vector is not (supi3_take's 1). */
int supi3_enter(void *uc, supi3_state *s, uint32_t number, uint32_t handler_mode, uint64_t vector_address) {
    uint32_t r[EXC_PC + 1];
    uint8_t bytes[4 * FRAME_WORDS];
    for (int k = 0; k <= EXC_PC; k++) {
        r[k] = core_read(uc, s, k);
    }
    int process = (r[EXC_CONTROL] & s->control_spsel) && !handler_mode;
    int64_t frame = ((int64_t)r[EXC_SP] - 4 * FRAME_WORDS) & ~(int64_t)7;
    uint32_t words[FRAME_WORDS] = {r[EXC_R0], r[EXC_R0 + 1], r[EXC_R0 + 2], r[EXC_R0 + 3], r[EXC_R0 + 4], r[EXC_LR],
                                   r[EXC_PC], r[EXC_XPSR] | (r[EXC_SP] & 4 ? s->xpsr_align : 0)};
    for (int k = 0; k < 4 * FRAME_WORDS; k++) {
        bytes[k] = (uint8_t)(words[k / 4] >> (8 * (k % 4)));
    }
    s->frame = frame;
    s->status = s->mem_write(uc, (uint64_t)frame, bytes, sizeof bytes);
    if (s->status != 0) {
        return 1;
    }
    core_write(uc, s, EXC_SP, (uint32_t)frame);
    if (process) {
        core_write(uc, s, EXC_CONTROL, r[EXC_CONTROL] & ~s->control_spsel); /* unicorn switches SP to the MSP */
    }
    uint32_t exc_return = handler_mode ? s->exc_return_handler
                          : process    ? s->exc_return_thread_psp
                                       : s->exc_return_thread_msp;
    return supi3_take(uc, s, number, exc_return, vector_address) ? 2 : 0;
}

/* CortexM.exception_return's traffic once it has found the return plain (an EXC_RETURN valid for the nesting, nothing
 * to tail-chain): the frame at the stack pointer EXC_RETURN names unstacked, R0-R3, R12, LR, then xPSR without the
 * alignment bit (the mode: it selects the SP), SPSEL set again on a return to the process stack, then SP (past the
 * frame and the alignment word) and PC. 1 if the frame is not in memory (nothing written; `frame`: its address). */
int supi3_return(void *uc, supi3_state *s, uint32_t exc_return) {
    int process = exc_return == s->exc_return_thread_psp;
    uint32_t sp = core_read(uc, s, process ? EXC_PSP : EXC_SP);
    uint8_t bytes[4 * FRAME_WORDS];
    uint32_t words[FRAME_WORDS];
    s->frame = sp;
    if (s->mem_read(uc, sp, bytes, sizeof bytes) != 0) {
        return 1;
    }
    for (int k = 0; k < FRAME_WORDS; k++) {
        words[k] = little_endian(bytes + 4 * k);
    }
    for (int k = 0; k < 6; k++) {
        core_write(uc, s, EXC_R0 + k, words[k]);
    }
    core_write(uc, s, EXC_XPSR, (words[7] & ~s->xpsr_align) | s->xpsr_t);
    if (process) {
        core_write(uc, s, EXC_CONTROL, core_read(uc, s, EXC_CONTROL) | s->control_spsel);
    }
    core_write(uc, s, EXC_SP, sp + 4 * FRAME_WORDS + (words[7] & s->xpsr_align ? 4 : 0));
    core_write(uc, s, EXC_PC, words[6] & ~1u);
    return 0;
}

/* The interrupt hook (uc_cb_hookintr_t): unicorn raised a CPU exception (the exception exit, SVC, BKPT, a prefetch
 * abort); note it and stop, CortexM takes it after the run (MCU-72: no Python call). */
void supi3_interrupt(void *uc, uint32_t number, void *data) {
    supi3_state *s = (supi3_state *)data;
    s->interrupt = number;
    s->emu_stop(uc);
}

/* MCU-51: the per-frame fast path. The board's /SS edges (GPIOA BSRR/BRR writes that change only /SS) and SPI1's DR
 * write that clocks a frame's byte are taken here, without Python, for frames whose whole effect on the Python model
 * is plain (supi3.mcu.frames decides which from its own tables and the model's state, hands them over at set-up and
 * refreshes what it mirrors after each Python write of GPIOA or SPI1: `valid`); any other write goes to Python's
 * write (`slow`). What the frames changed is noted here (`pending`) and set in the Python objects, as its net effect,
 * at the next entry into Python (supi3.mcu.frames.NativeFrames.catch_up). */
typedef void (*mmio_write_fn)(void *uc, uint64_t offset, unsigned size, uint64_t value, void *data);
typedef void (*bus_due_fn)(uint64_t offset, uint64_t value, uint64_t now); /* MCU-84: NativeFrames._bus_due */

/* The cost in cycles of a block's instructions before the PC of an access (CortexM.cycles_now's memo, MCU-1). */
typedef struct {
    uint64_t address; /* the block's first instruction; 0: an empty slot */
    uint64_t pc;
    uint64_t cycles;
} supi3_prefix;

typedef struct {
    supi3_state *state;
    supi3_held *spi;        /* SPI1's held register (MCU-25, MCU-26) */
    supi3_prefix *prefixes; /* CortexM.cycles_now's prefix costs, filled by Python */
    uint64_t prefix_mask;   /* slots - 1 (a power of two) */
    bus_due_fn bus_due;     /* MCU-84: Python runs the bus up to an /SS edge and mirrors the model again; 0: none */
    /* set up once from Python's tables (supi3.spi.upif, supi3.model.registers, the board's Table 3-7 limits) */
    int64_t least_t1, least_t2, least_t8; /* core cycles */
    uint64_t ss_pin, cd_command, cd_data, phase_command, phase_data;
    uint64_t sr_txe, sr_bsy, sr_rxne, spi_dr, spi_sr;
    int64_t least_t6max;  /* MCU-66: C/D follows the phase from t6 max after /SS rose (Board._inputs) */
    uint64_t irq_pin, cd_pin, io_pin; /* GPIOA's input pins the chip drives */
    uint64_t irq_address; /* MCU-67: the read-clear register /IRQ follows (IRQ_EVT, 3.4.14) */
    uint64_t irq_clear;   /* the bits a read of it clears */
    uint64_t io_bit;      /* the live I/O access bit a read of it joins */
    uint64_t exti_pr_offset; /* MCU-68: EXTI_PR's offset */
    /* MCU-78: the peripherals' configuration, refreshed by Python when what it is computed from changed */
    uint64_t gpio_ok;    /* GPIOA's clock on, not held in reset */
    uint64_t gpio_mask, gpio_pulled_up;
    uint64_t spi_ok;     /* SPI1 clocked, enabled master, 8 bits, mode 3, MSB first, SCLK period >= t0 */
    uint64_t period;     /* SCLK period in core cycles */
    uint64_t sr_modf;    /* SPI1's MODF flag in SR */
    uint64_t exti_rise;  /* MCU-67: a rise of /IRQ sets EXTI's pending bit (Exti.triggers) */
    /* refreshed by Python after each of its writes of GPIOA or SPI1 */
    uint64_t valid;      /* the fast path may run: Python's objects are as mirrored here */
    uint64_t due;        /* the first core cycle whose bus synchronisation would run a bus event */
    uint64_t latch;      /* the latch phase (3.4.14) */
    uint64_t latch_at;   /* the first core cycle whose synchronisation runs the latch phase's start (MCU-52) */
    uint64_t gpio_levels;
    uint64_t io;         /* MCU-66: the chip's I/O access bit */
    uint64_t io_at;      /* the first core cycle whose synchronisation sets it (the bench's `io` event) */
    /* the state the fast path runs on: refreshed by Python, changed here, read back by Python's catch-up */
    uint64_t pending;    /* a frame's effect not yet in the Python objects */
    uint64_t odr;
    uint64_t synced;     /* 1 + the latest core cycle the bus was synchronised to; 0: none */
    uint64_t phase, command, last_rx;
    uint64_t frame_open, frame_fall, frame_driven;
    uint64_t transfer, transfer_seen, transfer_start, transfer_period;
    int64_t ss_rise;
    uint64_t cd_before;
    uint64_t irq_level;  /* /IRQ as the board last followed it (Board._irq_level) */
    uint64_t written;    /* a bit per address written */
    uint64_t cleared;    /* MCU-67: reads of the register /IRQ follows taken here */
    uint64_t cleared_at; /* 1 + the core cycle of the latest of them */
    uint64_t exti_pr;    /* MCU-68: EXTI's PR */
    uint64_t dr_writes, rx_last, shift_received, shift_start, shift_end;
    uint64_t taken;      /* accesses taken here since set-up (a count for tests and benchmarks) */
    /* MCU-86: EXTI0's handler's return tail-chained here (tail_chain). Set once: */
    uint64_t exception_exit;   /* unicorn's interrupt number of a branch to an EXC_RETURN value */
    uint64_t primask_register; /* unicorn's number of PRIMASK */
    uint64_t chain_number;     /* EXTI0's exception number */
    uint64_t tail_chain_cycles;
    uint64_t return_cycles;    /* Cpu.return_cycles */
    uint64_t idle_loop;        /* the halfword of `b .` (MCU-4) */
    /* mirrored by Python with the rest (refresh): */
    uint64_t chain_leave;    /* the return Python would only decide by EXTI0's line (NativeFrames._chain_leave) */
    uint64_t chain_pending;  /* EXTI0 pending (pended again while active, MCU-81) */
    uint64_t exti_imr;       /* EXTI's IMR */
    int64_t irq_fell;        /* Board._irq_fell, -1: none */
    uint64_t chain_vector;   /* VTOR + 4 * chain_number */
    uint64_t thread_deadline; /* the step's deadline once EXTI0 has returned (Board._deadline_of the next bus event, the step's other bounds) */
    /* what the returns taken here since the last catch-up did (NativeFrames._chained): */
    uint64_t chains;
    uint64_t returned;       /* a plain return to thread mode (the last: EXTI0 is no longer active) */
    int64_t chain_latency;   /* the longest /IRQ latency of their entries in core cycles, -1: none measured */
    uint8_t values[16];   /* what a read of each address returns (fast reads only) */
    uint8_t written_values[16];
    uint8_t plain[256];   /* upif._PLAIN_COMMANDS */
    uint8_t address[256]; /* each command byte's address, rd and wr (upif._COMMANDS) */
    uint8_t rd[256];
    uint8_t wr[256];
    uint8_t reads_register[16];  /* upif._READS_REGISTER */
    uint8_t writes_register[16]; /* upif._WRITES_REGISTER */
    uint8_t fast_read[16];       /* a read without side effects: 1, 2 = a data register (not in the latch phase) */
    uint8_t fast_write[16];      /* a write that only stores: 1, 2 = a data register (not in the latch phase) */
    uint8_t write_mask[16];
    int8_t alias[16];            /* the address a written register is read at, or -1 */
} supi3_frames;

typedef struct {
    supi3_frames *frames;
    mmio_write_fn slow; /* the peripheral's write in Python */
    uint64_t port;      /* 0: GPIOA, 1: SPI1, 2: EXTI */
    supi3_held *held;   /* the peripheral's held register: its reads not taken here go to supi3_held_read */
} supi3_port;

/* The slot of a block's prefix cost (CortexM._prefix_slot computes the same; a PC is reached from more than one block). */
static uint64_t prefix_slot(uint64_t address, uint64_t pc) { return (pc >> 1) * 31 + (address >> 1); }

/* CortexM.cycles_now within the access, if its prefix cost is known: 0 (and nothing) if not. */
static int frames_now(const supi3_frames *f, uint64_t *now) {
    const supi3_state *s = f->state;
    uint64_t start = s->block_start;
    if (s->access_pc > s->block_address) {
        const supi3_prefix *p = &f->prefixes[prefix_slot(s->block_address, s->access_pc) & f->prefix_mask];
        if (p->address != s->block_address || p->pc != s->access_pc || p->address == 0) {
            return 0;
        }
        start += p->cycles;
    }
    *now = start > s->handed ? start : s->handed;
    return 1;
}

/* An access of `address` at `now` without side effects: a data register only outside the latch phase, which begins at
 * `latch_at` if it has not begun (MCU-52: the phase events the native frames pass over). */
static int fast_access(const supi3_frames *f, const uint8_t *table, unsigned address, uint64_t now) {
    return table[address] == 1 || (table[address] == 2 && !f->latch && now < f->latch_at);
}

/* MCU-66: the chip's I/O access bit at `now` (the bench's `io` event sets it; only a cycle's end, past `due`, clears
 * it). */
static uint64_t io_now(const supi3_frames *f, uint64_t now) { return f->io || now >= f->io_at; }

/* MCU-67: a read of the register /IRQ follows at `now` (RegisterFile.cpu_read: its value with the live I/O access bit
 * joined; the bits read cleared), if /IRQ's rise it may cause sets no pending bit of EXTI (Board._follow_irq: then
 * nothing else changes, the board's request already settled when the mirror was made). The read is noted for the
 * catch-up, which makes it in the register file. */
static int read_clear(supi3_frames *f, unsigned address, uint64_t now, uint64_t *driven) {
    uint8_t value = f->values[address];
    uint8_t left = (uint8_t)(value & ~f->irq_clear);
    if (left == 0 && f->irq_level == 0 && f->exti_rise) {
        return 0;
    }
    *driven = value | (io_now(f, now) << f->io_bit);
    f->values[address] = left;
    f->irq_level = left == 0;
    f->cleared += 1;
    f->cleared_at = now + 1;
    return 1;
}

/* /SS fell at `now`: Board._ss_edge's t8 check and UpifProtocol.begin, if plain. */
static int frame_fall(supi3_frames *f, uint64_t now) {
    if (f->frame_open || (int64_t)now - f->ss_rise < f->least_t8) {
        return 0;
    }
    uint64_t driven = f->last_rx;
    if (f->phase == f->phase_data) {
        unsigned command = (unsigned)f->command & 0xFF;
        unsigned address = f->address[command];
        if (f->rd[command] && f->reads_register[address]) {
            if (address == f->irq_address) {
                if (!read_clear(f, address, now, &driven)) {
                    return 0;
                }
            } else if (!fast_access(f, f->fast_read, address, now)) {
                return 0;
            } else {
                driven = f->values[address];
            }
        }
    } else if (f->phase != f->phase_command) {
        return 0;
    }
    f->frame_open = 1;
    f->frame_fall = now;
    f->frame_driven = driven;
    f->transfer = 0;
    return 1;
}

/* /SS rose at `now`: Board._ss_edge's edge count and t2 check and UpifProtocol.end, if plain. */
static int frame_rise(supi3_frames *f, uint64_t now) {
    if (!f->frame_open || !f->transfer || (now - f->transfer_start) / f->transfer_period < 8
        || (int64_t)(now - (f->transfer_start + 8 * f->transfer_period)) < f->least_t2) {
        return 0;
    }
    unsigned rx = (unsigned)f->transfer_seen;
    if (f->phase == f->phase_command) {
        if (!f->plain[rx]) {
            return 0;
        }
        f->cd_before = f->cd_command;
        f->command = rx;
        f->phase = f->phase_data;
    } else { /* the data phase (frame_fall took no other) */
        unsigned command = (unsigned)f->command & 0xFF;
        unsigned address = f->address[command];
        if (f->writes_register[address] && f->wr[command]) {
            if (!fast_access(f, f->fast_write, address, now)) {
                return 0;
            }
            uint8_t value = (uint8_t)(rx & f->write_mask[address]);
            f->written |= 1u << address;
            f->written_values[address] = value;
            if (f->alias[address] >= 0) {
                f->values[f->alias[address]] = value;
            }
        }
        f->cd_before = f->cd_data;
        f->phase = f->phase_command;
    }
    f->last_rx = rx;
    f->frame_open = 0;
    f->transfer = 0;
    f->ss_rise = (int64_t)now;
    return 1;
}

/* SPI1's DR written at `now`: Spi.write's release of the read taken, its start of the byte (Board.spi_byte's checks)
 * and its hold of SR and offer of DR (Spi._hold), if plain. */
static int frame_byte(supi3_frames *f, uint64_t now, uint64_t value) {
    supi3_held *h = f->spi;
    if (!f->spi_ok || !f->frame_open || f->transfer || !h->held || h->offset != f->spi_sr || !h->taken || h->once
        || h->once_offset != f->spi_dr || (int64_t)(now + f->period / 2 - f->frame_fall) < f->least_t1) {
        return 0;
    }
    uint64_t end = now + 8 * f->period;
    f->rx_last = h->once_value;
    f->transfer = 1;
    f->transfer_seen = value & 0xFF;
    f->transfer_start = now;
    f->transfer_period = f->period;
    f->dr_writes += 1;
    f->shift_received = f->frame_driven;
    f->shift_start = now;
    f->shift_end = end;
    h->until = end;
    h->offset = (uint32_t)f->spi_sr;
    h->value = (uint32_t)(f->sr_txe | f->sr_bsy | f->sr_modf);
    h->held = 1;
    h->poll = 1;
    h->after = (uint32_t)(f->sr_rxne | f->sr_txe | f->sr_modf);
    h->has_after = 1;
    h->once_from = end;
    h->once_at = 0;
    h->once_offset = (uint32_t)f->spi_dr;
    h->once_value = (uint32_t)f->frame_driven;
    h->once = 1;
    h->taken = 0;
    h->once_then = (uint32_t)(f->sr_txe | f->sr_modf);
    return 1;
}

/* MCU-68: EXTI's register `offset` written with `value`: PR (Exti.write: a 1 clears its bit) taken here at the access's
 * time, if no bus event is due (Board._exti_write synchronises the bus first). Its request (Board._request) has nothing
 * to do: the mirror is valid only while /IRQ's line does not request or its exception is active or pending (refresh),
 * and a write of PR only clears bits. */
static int exti_write(supi3_frames *f, uint64_t offset, uint64_t value) {
    uint64_t now = 0;
    if (offset != f->exti_pr_offset || !frames_now(f, &now) || now >= f->due) {
        return 0;
    }
    f->exti_pr &= ~value;
    f->synced = now + 1;
    f->pending = 1;
    f->state->handed = now;
    return 1;
}

/* GPIOA's BSRR (0x10) or BRR (0x14) written with `value`: a write that changes no pin, or an /SS edge of a plain frame
 * (frame_fall, frame_rise), taken here (1), else left to Python (0). MCU-84: an edge with a bus event due at or before
 * it (`due`) has Python run the bus up to the edge and mirror the model again (`bus_due`, what Board._on_output does
 * before the edge), then is taken here if the new mirror is valid and the edge plain before the next bus event (the
 * same write once more, `may_sync` = 0: Python's write takes it otherwise). */
static int gpio_write(supi3_frames *f, uint64_t offset, uint64_t value, int may_sync) {
    supi3_state *s = f->state;
    uint64_t now = 0;
    uint64_t odr = offset == 0x10 ? ((f->odr & ~(value >> 16)) | value) & 0xFFFF : f->odr & ~value & 0xFFFF;
    uint64_t levels = (odr & f->gpio_mask) | (f->gpio_pulled_up & ~f->gpio_mask);
    uint64_t changed = levels ^ f->gpio_levels;
    int taken = changed == 0;
    if (changed == (uint64_t)1 << f->ss_pin && frames_now(f, &now)) {
        if (now >= f->due) {
            if (!may_sync || f->bus_due == 0) {
                return 0;
            }
            s->handed = now; /* MCU-90: the edge's time handed to Python, as CortexM.cycles_now hands it out */
            f->bus_due(offset, value, now);
            return f->valid && !s->stop_request && f->gpio_ok && gpio_write(f, offset, value, 0);
        }
        taken = levels >> f->ss_pin & 1 ? frame_rise(f, now) : frame_fall(f, now);
        if (taken) {
            f->synced = now + 1;
            s->handed = now;
        }
    }
    if (taken) {
        f->odr = odr;
        f->gpio_levels = levels;
        f->pending = 1;
    }
    return taken;
}

/* The write callback (uc_cb_mmio_write_t) of GPIOA, SPI1 and EXTI: a frame's edge or byte, or EXTI's PR write, taken
 * here, or Python's write. */
void supi3_port_write(void *uc, uint64_t offset, unsigned size, uint64_t value, void *data) {
    supi3_port *p = (supi3_port *)data;
    supi3_frames *f = p->frames;
    supi3_state *s = f->state;
    uint64_t now = 0;
    if (f->valid && !s->stop_request) {
        if (p->port == 2) {
            if (exti_write(f, offset, value)) {
                f->taken += 1;
                return;
            }
        } else if (p->port == 1) {
            if (offset == f->spi_dr && frames_now(f, &now) && now < f->due && frame_byte(f, now, value)) {
                f->synced = now + 1;
                f->pending = 1;
                f->taken += 1;
                s->handed = now;
                return;
            }
        } else if (f->gpio_ok && (offset == 0x10 || offset == 0x14) && gpio_write(f, offset, value, 1)) {
            f->taken += 1;
            return;
        }
    }
    p->slow(uc, offset, size, value, 0);
}

/* MCU-66: GPIOA's register `offset` as Gpio.read would answer it at `now`, if a pure function of the mirrored state:
 * IDR (the chip's /IRQ, C/D and I/O access pins by Board._inputs, the outputs' ODR), ODR, and the offsets that read 0;
 * not CRL and CRH (not mirrored). The inputs need the bus synchronised to `now` without a bus event (`due`); the I/O
 * access bit is set by the bench's `io` event, which the synchronisation runs from `io_at` on; C/D follows the phase
 * from t6 max after /SS rose, the level before until then. */
static int gpio_read(supi3_frames *f, uint64_t offset, uint64_t *value) {
    if (offset == 0xC) {
        *value = f->odr;
        return 1;
    }
    if (offset >= 0x10) {
        *value = 0;
        return 1;
    }
    uint64_t now = 0;
    if (offset != 0x8 || !frames_now(f, &now) || now >= f->due) {
        return 0;
    }
    uint64_t io = io_now(f, now);
    uint64_t cd = f->cd_before;
    if ((int64_t)now >= f->ss_rise + f->least_t6max) {
        cd = f->phase == f->phase_command ? f->cd_command : f->cd_data;
    }
    uint64_t inputs = (f->irq_level << f->irq_pin) | (cd << f->cd_pin) | (io << f->io_pin);
    *value = ((inputs & ~f->gpio_mask) | (f->odr & f->gpio_mask)) & 0xFFFF;
    f->synced = now + 1;
    f->pending = 1;
    f->state->handed = now;
    return 1;
}

/* The read callback (uc_cb_mmio_read_t) of GPIOA, SPI1 and EXTI: a GPIOA read taken here (MCU-66), or the held register's
 * read (supi3_held_read), which answers SPI1's held and offered registers and calls Python's read for the rest. */
uint64_t supi3_port_read(void *uc, uint64_t offset, unsigned size, void *data) {
    supi3_port *p = (supi3_port *)data;
    supi3_frames *f = p->frames;
    uint64_t value = 0;
    if (p->port == 0 && f->valid && !f->state->stop_request && f->gpio_ok && gpio_read(f, offset, &value)) {
        f->taken += 1;
        return value;
    }
    return supi3_held_read(uc, offset, size, p->held);
}

/* MCU-86: the run stopped at an exception return (`pc`: its EXC_RETURN) of EXTI0's handler. Python's return
 * (CortexM.exception_return, Board._returning) would run the bus up to the return, let the NVIC sample EXTI0's line and
 * tail-chain into it if it is pending again, else unstack the frame; it is taken here, as that path takes it, when
 * that is all it would do: the mirror valid, Python's leave (EXTI0 alone active and at most itself pending, enabled,
 * the run not at its end), no stop asked, no code written, the deadline and the next bus event (`due`: the flag events
 * before it only set the chip's flags, which the catch-up's synchronisation runs, MCU-52) after the return, EXC_RETURN
 * a return to thread mode (the only valid one with one exception active, B1.5.8), and PRIMASK clear (a priority is a
 * byte, below thread mode's 256, B1.5.4). EXTI0 pending or its line asserted: the tail-chain, if its vector is in
 * memory with bit 0 set. Else the plain return, if the frame is in memory and the code returned to is not `b .` (a
 * wait the run loop takes without running it, MCU-4); the step's deadline becomes the run loop's for thread mode. The
 * effects on Python's objects (EXTI0 no longer pending or active, the entry's count and latency) are counted for the
 * catch-up. 1: taken. */
static int exti0_return(void *uc, supi3_frames *f) {
    supi3_state *s = f->state;
    uint32_t exc_return = (uint32_t)s->pc | 1u;
    uint64_t now = s->cycles;
    uint64_t primask = 0;
    uint8_t bytes[4];
    if (!f->valid || !f->chain_leave || s->stop_request || s->code_written || now >= s->deadline || now >= f->due ||
        (exc_return != s->exc_return_thread_msp && exc_return != s->exc_return_thread_psp)) {
        return 0;
    }
    s->reg_read(uc, (int)f->primask_register, &primask);
    if (primask & 1) {
        return 0;
    }
    if (f->chain_pending || (f->exti_pr & f->exti_imr & 1)) {
        if (s->mem_read(uc, f->chain_vector, bytes, sizeof bytes) != 0 || !(little_endian(bytes) & 1)) {
            return 0;
        }
        supi3_take(uc, s, (uint32_t)f->chain_number, exc_return, f->chain_vector);
        s->cycles = now + f->tail_chain_cycles;
        if (f->irq_fell >= 0) {
            int64_t latency = (int64_t)s->cycles - f->irq_fell;
            f->chain_latency = latency > f->chain_latency ? latency : f->chain_latency;
            f->irq_fell = -1;
        }
        f->chain_pending = 0;
        f->chains += 1;
    } else {
        uint32_t sp = core_read(uc, s, exc_return == s->exc_return_thread_psp ? EXC_PSP : EXC_SP);
        uint8_t code[2];
        if (s->mem_read(uc, (uint64_t)sp + 24, bytes, sizeof bytes) != 0 ||
            s->mem_read(uc, little_endian(bytes) & ~1u, code, sizeof code) != 0 ||
            (code[0] | (uint64_t)code[1] << 8) == f->idle_loop || supi3_return(uc, s, exc_return) != 0) {
            return 0;
        }
        s->cycles = now + f->return_cycles;
        s->deadline = s->deadline < f->thread_deadline ? s->deadline : f->thread_deadline;
        f->returned = 1; /* no other return follows in this run: an entry is Python's */
    }
    f->synced = now + 1;
    f->pending = 1;
    return 1;
}

/* A run from the PC (its Thumb bit set) until a hook stops it (MCU-72): no interrupt yet, the PC afterwards in `pc`;
 * unicorn's status. An exception return exti0_return takes runs on from the code it returns to (MCU-86). */
int supi3_run(void *uc, supi3_state *s, supi3_frames *f) {
    int status = 0;
    do {
        uint64_t pc = 0;
        s->interrupt = s->no_interrupt;
        s->reg_read(uc, s->pc_register, &pc);
        status = s->emu_start(uc, pc | 1, 0, 0, 0);
        s->pc = 0;
        s->reg_read(uc, s->pc_register, &s->pc);
    } while (status == 0 && s->interrupt == f->exception_exit && exti0_return(uc, f));
    return status;
}

/* The layout of the structs above as this compiler lays them out: the number of values after it, the struct's size, then each
 * field's offset in the order of its declaration. supi3.mcu.hook checks its ctypes mirrors against them when it loads
 * the library (MCU-25): a mismatch is a NativeHookError, not memory written at the wrong place. */
#define AT(type, field) (uint32_t) offsetof(type, field)
const uint32_t supi3_block_layout[] = {7, sizeof(supi3_block), AT(supi3_block, address), AT(supi3_block, size),
                                       AT(supi3_block, instructions), AT(supi3_block, cycles),
                                       AT(supi3_block, countdown), AT(supi3_block, poll)};
const uint32_t supi3_state_layout[] = {
    43, sizeof(supi3_state), AT(supi3_state, cycles), AT(supi3_state, instructions), AT(supi3_state, deadline),
    AT(supi3_state, block_start), AT(supi3_state, block_address), AT(supi3_state, block_end),
    AT(supi3_state, skip_until), AT(supi3_state, skip_address), AT(supi3_state, handed),
    AT(supi3_state, skip_pending), AT(supi3_state, stop_request), AT(supi3_state, skip_polls), AT(supi3_state, mask),
    AT(supi3_state, block_poll), AT(supi3_state, cache), AT(supi3_state, fresh), AT(supi3_state, access_pc),
    AT(supi3_state, low_registers), AT(supi3_state, pc_register), AT(supi3_state, emu_stop),
    AT(supi3_state, reg_read), AT(supi3_state, reg_write), AT(supi3_state, describe), AT(supi3_state, rewritable),
    AT(supi3_state, rewritable_size), AT(supi3_state, code_written), AT(supi3_state, mem_read),
    AT(supi3_state, mem_write), AT(supi3_state, emu_start), AT(supi3_state, exc_registers),
    AT(supi3_state, exc_return_handler), AT(supi3_state, exc_return_thread_msp), AT(supi3_state, exc_return_thread_psp),
    AT(supi3_state, xpsr_t), AT(supi3_state, xpsr_align), AT(supi3_state, control_spsel), AT(supi3_state, interrupt),
    AT(supi3_state, no_interrupt), AT(supi3_state, frame), AT(supi3_state, vector), AT(supi3_state, pc),
    AT(supi3_state, status)};
const uint32_t supi3_held_layout[] = {
    17, sizeof(supi3_held), AT(supi3_held, state), AT(supi3_held, slow), AT(supi3_held, until), AT(supi3_held, offset),
    AT(supi3_held, value), AT(supi3_held, held), AT(supi3_held, poll), AT(supi3_held, after),
    AT(supi3_held, has_after), AT(supi3_held, once_from), AT(supi3_held, once_at), AT(supi3_held, once_offset),
    AT(supi3_held, once_value), AT(supi3_held, once), AT(supi3_held, taken), AT(supi3_held, once_then)};
const uint32_t supi3_prefix_layout[] = {
    4, sizeof(supi3_prefix), AT(supi3_prefix, address), AT(supi3_prefix, pc), AT(supi3_prefix, cycles)};
const uint32_t supi3_frames_layout[] = {
    94, sizeof(supi3_frames), AT(supi3_frames, state), AT(supi3_frames, spi), AT(supi3_frames, prefixes),
    AT(supi3_frames, prefix_mask), AT(supi3_frames, bus_due), AT(supi3_frames, least_t1), AT(supi3_frames, least_t2),
    AT(supi3_frames, least_t8), AT(supi3_frames, ss_pin), AT(supi3_frames, cd_command), AT(supi3_frames, cd_data),
    AT(supi3_frames, phase_command), AT(supi3_frames, phase_data), AT(supi3_frames, sr_txe),
    AT(supi3_frames, sr_bsy), AT(supi3_frames, sr_rxne), AT(supi3_frames, spi_dr), AT(supi3_frames, spi_sr),
    AT(supi3_frames, least_t6max), AT(supi3_frames, irq_pin), AT(supi3_frames, cd_pin), AT(supi3_frames, io_pin),
    AT(supi3_frames, irq_address), AT(supi3_frames, irq_clear), AT(supi3_frames, io_bit),
    AT(supi3_frames, exti_pr_offset), AT(supi3_frames, gpio_ok), AT(supi3_frames, gpio_mask),
    AT(supi3_frames, gpio_pulled_up), AT(supi3_frames, spi_ok), AT(supi3_frames, period), AT(supi3_frames, sr_modf),
    AT(supi3_frames, exti_rise), AT(supi3_frames, valid), AT(supi3_frames, due), AT(supi3_frames, latch),
    AT(supi3_frames, latch_at), AT(supi3_frames, gpio_levels), AT(supi3_frames, io), AT(supi3_frames, io_at),
    AT(supi3_frames, pending), AT(supi3_frames, odr), AT(supi3_frames, synced), AT(supi3_frames, phase),
    AT(supi3_frames, command), AT(supi3_frames, last_rx), AT(supi3_frames, frame_open),
    AT(supi3_frames, frame_fall), AT(supi3_frames, frame_driven), AT(supi3_frames, transfer),
    AT(supi3_frames, transfer_seen), AT(supi3_frames, transfer_start), AT(supi3_frames, transfer_period),
    AT(supi3_frames, ss_rise), AT(supi3_frames, cd_before), AT(supi3_frames, irq_level), AT(supi3_frames, written),
    AT(supi3_frames, cleared), AT(supi3_frames, cleared_at), AT(supi3_frames, exti_pr), AT(supi3_frames, dr_writes),
    AT(supi3_frames, rx_last), AT(supi3_frames, shift_received), AT(supi3_frames, shift_start),
    AT(supi3_frames, shift_end), AT(supi3_frames, taken), AT(supi3_frames, exception_exit),
    AT(supi3_frames, primask_register), AT(supi3_frames, chain_number), AT(supi3_frames, tail_chain_cycles),
    AT(supi3_frames, return_cycles), AT(supi3_frames, idle_loop),
    AT(supi3_frames, chain_leave), AT(supi3_frames, chain_pending), AT(supi3_frames, exti_imr),
    AT(supi3_frames, irq_fell), AT(supi3_frames, chain_vector), AT(supi3_frames, thread_deadline),
    AT(supi3_frames, chains), AT(supi3_frames, returned),
    AT(supi3_frames, chain_latency), AT(supi3_frames, values),
    AT(supi3_frames, written_values), AT(supi3_frames, plain), AT(supi3_frames, address), AT(supi3_frames, rd),
    AT(supi3_frames, wr), AT(supi3_frames, reads_register), AT(supi3_frames, writes_register),
    AT(supi3_frames, fast_read), AT(supi3_frames, fast_write), AT(supi3_frames, write_mask),
    AT(supi3_frames, alias)};
const uint32_t supi3_memory_layout[] = {
    12, sizeof(supi3_memory), AT(supi3_memory, state), AT(supi3_memory, flash), AT(supi3_memory, flash_size),
    AT(supi3_memory, never_low), AT(supi3_memory, never_high), AT(supi3_memory, fetch), AT(supi3_memory, store),
    AT(supi3_memory, prot_write), AT(supi3_memory, prot_exec), AT(supi3_memory, prot_all),
    AT(supi3_memory, prefetch_abort)};
const uint32_t supi3_port_layout[] = {
    5, sizeof(supi3_port), AT(supi3_port, frames), AT(supi3_port, slow), AT(supi3_port, port), AT(supi3_port, held)};
