/*
 * QEMU TCG plugin (API v1, qemu-system-arm 7.2) counting executed guest
 * instructions exactly, for the interrupt-cost benchmark (tools/bench).
 * Debian ships no qemu-plugin.h: the few prototypes used are declared here as
 * in QEMU 7.2's include/qemu/qemu-plugin.h.
 *
 * Arguments (-plugin bench_plugin.so,arg=...,arg=...):
 *   out=FILE      results
 *   begin=ADDR    first instruction of the begin marker (hex, Thumb bit ignored)
 *   end=ADDR      first instruction of an end marker; repeat for section 0, 1, ...
 *   syms=FILE     optional: "start size name" lines (hex start, decimal size) of
 *                 the guest's functions, for a flat per-function profile
 *   pcsec=N       optional: per-instruction-address counts of the windows that
 *                 end in section N ("A addr count" at exit; slower: one
 *                 callback per instruction; addresses below 1 MB only)
 *   cycles=m0plus optional: also a Cortex-M0+ cycle bound per window,
 *                 "C i cycles cond_branches" after its "S" line: every
 *                 instruction weighted by its cycle count in the Cortex-M0+
 *                 Technical Reference Manual (ARM DDI 0484C, Table 3-1:
 *                 loads and stores 2, LDM/STM/PUSH 1+N, POP 1+N or 3+N with PC,
 *                 B and BX 2, BL 3, MULS 1 with the single-cycle multiplier, the
 *                 rest 1), a conditional branch counted as taken (2): the true
 *                 count lies in [cycles - cond_branches, cycles] (zero-wait-state
 *                 memory)
 * Every instruction adds 1 to a global counter (and to its function's counter)
 * with an inline operation. When the begin marker's first instruction is
 * reached the counters are snapshot; when end marker i's is reached, the
 * difference is written as "S i count" and the functions' differences are
 * added to section i's profile. At exit: "F i name count entries" per function
 * with a non-zero count (entries: executions of its first instruction, i.e.
 * calls, loop back-edges to the entry aside). Counts are deterministic (no timing involved).
 */
#include <inttypes.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- QEMU 7.2 plugin API v1 (subset) ---------------------------------- */
typedef uint64_t qemu_plugin_id_t;
typedef struct {
    const char *target_name;
    struct {
        int min;
        int cur;
    } version;
    bool system_emulation;
    union {
        struct {
            int smp_vcpus;
            int max_vcpus;
        } system;
    };
} qemu_info_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_CB_R_REGS, QEMU_PLUGIN_CB_RW_REGS };
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn,
                                            qemu_plugin_vcpu_udata_cb_t cb,
                                            enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_vcpu_insn_exec_inline(struct qemu_plugin_insn *insn,
                                                enum qemu_plugin_op op, void *ptr, uint64_t imm);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t idx);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);
const void *qemu_plugin_insn_data(const struct qemu_plugin_insn *insn);
size_t qemu_plugin_insn_size(const struct qemu_plugin_insn *insn);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);
void qemu_plugin_outs(const char *string);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;
__attribute__((visibility("default"))) int
qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv);
/* ----------------------------------------------------------------------- */

#define MAX_END 8
#define MAX_SYMS 8192

typedef struct {
    uint64_t start, size;
    char *name;
} sym_t;

static FILE *out;
static uint64_t begin_addr = UINT64_MAX;
static uint64_t end_addr[MAX_END];
static int n_end;
static uint64_t icount; /* all instructions */
static uint64_t icount0;
static bool open_window;
static sym_t syms[MAX_SYMS];
static int n_syms;
static uint64_t fcount[MAX_SYMS + 1]; /* last slot: not in any symbol */
static uint64_t fsnap[MAX_SYMS + 1];
static uint64_t fprof[MAX_END][MAX_SYMS + 1];
static uint64_t fentry[MAX_SYMS + 1]; /* executions of each function's first instruction */
static uint64_t esnap[MAX_SYMS + 1];
static uint64_t eprof[MAX_END][MAX_SYMS + 1];
#define PC_SLOTS (1u << 19) /* halfword slots of the first 1 MB of code */
#define PC_TOUCH_MAX (1u << 20)
static int pc_sec = -1;
static uint32_t *pc_pending; /* counts of the open window */
static uint64_t *pc_total;   /* of the windows of section pc_sec */
static uint32_t *pc_touched; /* slots incremented in the open window, in order */
static uint32_t pc_n_touched;
static bool cycles_m0plus;
static uint64_t ccount, ccount0; /* Cortex-M0+ cycles, conditional branches as taken */
static uint64_t bcount, bcount0; /* conditional branches executed */

static unsigned popcount8(unsigned v)
{
    unsigned n = 0;
    for (; v != 0u; v &= v - 1u) {
        n++;
    }
    return n;
}

/* Cycles of one ARMv6-M instruction on a Cortex-M0+ (ARM DDI 0484C, Table 3-1),
 * a conditional branch as taken; *cond = 1 for a conditional branch. */
static unsigned m0plus_cycles(const uint8_t *b, size_t size, unsigned *cond)
{
    *cond = 0u;
    const unsigned h = (unsigned)b[0] | ((unsigned)b[1] << 8);
    if (size == 4u) {
        return 3u; /* BL; MSR, MRS, DMB, DSB, ISB: the other 32-bit ones */
    }
    if ((h >> 11) == 0x09u || (h >> 12) == 0x5u || (h >> 13) == 0x3u || (h >> 12) == 0x8u ||
        (h >> 12) == 0x9u) {
        return 2u; /* LDR literal, register offset, immediate, halfword, SP-relative; STR */
    }
    if ((h & 0xFE00u) == 0xB400u) {
        return 1u + popcount8(h & 0xFFu) + ((h >> 8) & 1u); /* PUSH {..., LR} */
    }
    if ((h & 0xFE00u) == 0xBC00u) {
        const unsigned pc = (h >> 8) & 1u;
        return 1u + popcount8(h & 0xFFu) + pc + 2u * pc; /* POP, 3 + N with PC */
    }
    if ((h >> 12) == 0xCu) {
        return 1u + popcount8(h & 0xFFu); /* LDM, STM */
    }
    if ((h >> 12) == 0xDu && ((h >> 8) & 0xEu) != 0xEu) {
        *cond = 1u;
        return 2u; /* B<cond>: 2 taken, 1 not */
    }
    if ((h >> 11) == 0x1Cu || (h & 0xFF00u) == 0x4700u) {
        return 2u; /* B, BX, BLX */
    }
    return 1u;
}

static int sym_index(uint64_t a)
{
    int lo = 0, hi = n_syms - 1;
    while (lo <= hi) {
        const int mid = (lo + hi) / 2;
        if (a < syms[mid].start) {
            hi = mid - 1;
        } else if (a >= syms[mid].start + syms[mid].size) {
            lo = mid + 1;
        } else {
            return mid;
        }
    }
    return n_syms; /* unknown */
}

static void pc_clear(bool keep)
{
    for (uint32_t i = 0; i < pc_n_touched; i++) {
        const uint32_t slot = pc_touched[i];
        if (keep) {
            pc_total[slot] += pc_pending[slot];
        }
        pc_pending[slot] = 0u;
    }
    pc_n_touched = 0u;
}

static void on_insn(unsigned int vcpu, void *ud)
{
    (void)vcpu;
    const uint32_t slot = (uint32_t)(uintptr_t)ud;
    if (open_window && pc_n_touched < PC_TOUCH_MAX) {
        if (pc_pending[slot]++ == 0u) {
            pc_touched[pc_n_touched++] = slot;
        }
    }
}

static void on_begin(unsigned int vcpu, void *ud)
{
    (void)vcpu;
    (void)ud;
    if (pc_sec >= 0) {
        pc_clear(false);
    }
    icount0 = icount;
    ccount0 = ccount;
    bcount0 = bcount;
    memcpy(fsnap, fcount, sizeof(uint64_t) * (size_t)(n_syms + 1));
    memcpy(esnap, fentry, sizeof(uint64_t) * (size_t)(n_syms + 1));
    open_window = true;
}

static void on_end(unsigned int vcpu, void *ud)
{
    (void)vcpu;
    const int sec = (int)(uintptr_t)ud;
    if (!open_window) {
        return;
    }
    open_window = false;
    if (pc_sec >= 0) {
        pc_clear(sec == pc_sec);
    }
    fprintf(out, "S %d %" PRIu64 "\n", sec, icount - icount0);
    if (cycles_m0plus) {
        fprintf(out, "C %d %" PRIu64 " %" PRIu64 "\n", sec, ccount - ccount0, bcount - bcount0);
    }
    for (int i = 0; i <= n_syms; i++) {
        fprof[sec][i] += fcount[i] - fsnap[i];
        eprof[sec][i] += fentry[i] - esnap[i];
    }
}

static void on_trans(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    const size_t n = qemu_plugin_tb_n_insns(tb);
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        const uint64_t a = qemu_plugin_insn_vaddr(insn) & ~(uint64_t)1;
        /* Marker callbacks first, so they see the counters before this
         * instruction (the same for begin and end: the difference is exact). */
        if (a == begin_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_begin, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        for (int e = 0; e < n_end; e++) {
            if (a == end_addr[e]) {
                qemu_plugin_register_vcpu_insn_exec_cb(insn, on_end, QEMU_PLUGIN_CB_NO_REGS,
                                                       (void *)(uintptr_t)e);
            }
        }
        if (pc_sec >= 0 && a / 2u < PC_SLOTS) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_insn, QEMU_PLUGIN_CB_NO_REGS,
                                                   (void *)(uintptr_t)(a / 2u));
        }
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &icount, 1u);
        if (cycles_m0plus) {
            unsigned cond;
            const unsigned w =
                m0plus_cycles(qemu_plugin_insn_data(insn), qemu_plugin_insn_size(insn), &cond);
            qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &ccount,
                                                       w);
            if (cond != 0u) {
                qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64,
                                                           &bcount, 1u);
            }
        }
        if (n_syms > 0) {
            const int si = sym_index(a);
            qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64,
                                                       &fcount[si], 1u);
            if (si < n_syms && a == syms[si].start) {
                qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64,
                                                           &fentry[si], 1u);
            }
        }
    }
}

static void plugin_exit(qemu_plugin_id_t id, void *ud)
{
    (void)id;
    (void)ud;
    for (int s = 0; s < n_end; s++) {
        for (int i = 0; i <= n_syms; i++) {
            if (fprof[s][i] != 0u) {
                fprintf(out, "F %d %s %" PRIu64 " %" PRIu64 "\n", s,
                        i < n_syms ? syms[i].name : "?", fprof[s][i], eprof[s][i]);
            }
        }
    }
    for (uint32_t i = 0; pc_total != NULL && i < PC_SLOTS; i++) {
        if (pc_total[i] != 0u) {
            fprintf(out, "A %x %" PRIu64 "\n", i * 2u, pc_total[i]);
        }
    }
    fprintf(out, "T %" PRIu64 "\n", icount);
    fclose(out);
    out = NULL;
}

static int sym_cmp(const void *a, const void *b)
{
    const sym_t *x = a, *y = b;
    return (x->start > y->start) - (x->start < y->start);
}

static int load_syms(const char *path)
{
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        return -1;
    }
    char name[512];
    unsigned long long start, size;
    while (n_syms < MAX_SYMS && fscanf(f, "%llx %llu %511s", &start, &size, name) == 3) {
        if (size == 0u) {
            continue;
        }
        syms[n_syms].start = start & ~1ull;
        syms[n_syms].size = size;
        syms[n_syms].name = strdup(name);
        n_syms++;
    }
    fclose(f);
    qsort(syms, (size_t)n_syms, sizeof syms[0], sym_cmp);
    return 0;
}

int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv)
{
    (void)info;
    const char *path = NULL;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (strncmp(a, "out=", 4) == 0) {
            path = a + 4;
        } else if (strncmp(a, "begin=", 6) == 0) {
            begin_addr = strtoull(a + 6, NULL, 16) & ~1ull;
        } else if (strncmp(a, "end=", 4) == 0 && n_end < MAX_END) {
            end_addr[n_end++] = strtoull(a + 4, NULL, 16) & ~1ull;
        } else if (strncmp(a, "pcsec=", 6) == 0) {
            pc_sec = atoi(a + 6);
            pc_pending = calloc(PC_SLOTS, sizeof *pc_pending);
            pc_total = calloc(PC_SLOTS, sizeof *pc_total);
            pc_touched = calloc(PC_TOUCH_MAX, sizeof *pc_touched);
            if (pc_pending == NULL || pc_total == NULL || pc_touched == NULL) {
                return -1;
            }
        } else if (strcmp(a, "cycles=m0plus") == 0) {
            cycles_m0plus = true;
        } else if (strncmp(a, "syms=", 5) == 0) {
            if (load_syms(a + 5) != 0) {
                fprintf(stderr, "bench_plugin: cannot read %s\n", a + 5);
                return -1;
            }
        } else {
            fprintf(stderr, "bench_plugin: unknown argument %s\n", a);
            return -1;
        }
    }
    if (path == NULL || begin_addr == UINT64_MAX || n_end == 0) {
        fprintf(stderr, "bench_plugin: needs out=FILE, begin=ADDR and end=ADDR\n");
        return -1;
    }
    out = fopen(path, "w");
    if (out == NULL) {
        fprintf(stderr, "bench_plugin: cannot write %s\n", path);
        return -1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_trans);
    qemu_plugin_register_atexit_cb(id, plugin_exit, NULL);
    return 0;
}
