/*
 * icount.c: exact guest instruction counts between two marker functions, for QEMU's TCG
 * plugin API version 1 (QEMU 7.2, Debian bookworm). Debian ships no qemu-plugin.h, so the
 * handful of API functions used here are declared below with the signatures of that header.
 *
 * Every translation block adds its instruction count to a 64-bit counter when it starts
 * (an inline add, so counting is exact and cheap). A callback on the first instruction of
 * `start` records the counter; one on the first instruction of `stop` prints the difference:
 *
 *     icount <n> <instructions>
 *
 * n counts the measurements from 0. The difference includes a constant overhead (the call of
 * the marker functions); the firmware measures an empty window first and the figures in the
 * README are net of it.
 *
 * Arguments: start=0xADDR,stop=0xADDR (Thumb addresses, bit 0 ignored),out=FILE (default stderr),
 *            profile=N (optional): for measurement N only, also print `tb <addr> <instructions>`
 *            per translation-block start address (map them to functions with the symbol table).
 * Build:     gcc -O2 -shared -fPIC -o libicount.so icount.c
 * Use:       qemu-system-arm ... -plugin ./libicount.so,start=0x...,stop=0x...,out=icount.txt
 */
#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef uint64_t qemu_plugin_id_t;
typedef struct qemu_info_t qemu_info_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_CB_R_REGS, QEMU_PLUGIN_CB_RW_REGS };
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);

void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t idx);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);
void qemu_plugin_register_vcpu_tb_exec_inline(struct qemu_plugin_tb *tb, enum qemu_plugin_op op,
                                              void *ptr, uint64_t imm);
void qemu_plugin_register_vcpu_tb_exec_cb(struct qemu_plugin_tb *tb, qemu_plugin_vcpu_udata_cb_t cb,
                                          enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn,
                                            qemu_plugin_vcpu_udata_cb_t cb,
                                            enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;

static uint64_t counter;   /* instructions of every translation block entered so far */
static uint64_t start_at;  /* counter at the last start marker */
static uint64_t start_addr = UINT64_MAX, stop_addr = UINT64_MAX;
static unsigned measurements;
static int armed;
static FILE *out;
static long profile_n = -1;          /* measurement to profile, or -1 */

#define PROF_SLOTS 65536u
static uint64_t prof_addr[PROF_SLOTS], prof_count[PROF_SLOTS];

static void on_tb_exec(unsigned int vcpu, void *ud)
{
    (void)vcpu;
    if (!armed || (long)measurements != profile_n)
        return;
    uint64_t packed = (uint64_t)(uintptr_t)ud; /* addr << 16 | n_insns */
    uint64_t addr = packed >> 16, n = packed & 0xffff;
    uint32_t h = (uint32_t)(addr * 2654435761u) & (PROF_SLOTS - 1);
    while (prof_addr[h] != 0 && prof_addr[h] != addr + 1)
        h = (h + 1) & (PROF_SLOTS - 1);
    prof_addr[h] = addr + 1;
    prof_count[h] += n;
}

static void on_start(unsigned int vcpu, void *ud)
{
    (void)vcpu; (void)ud;
    start_at = counter;
    armed = 1;
}

static void on_stop(unsigned int vcpu, void *ud)
{
    (void)vcpu; (void)ud;
    if (armed) {
        if ((long)measurements == profile_n) {
            for (unsigned h = 0; h < PROF_SLOTS; h++)
                if (prof_addr[h])
                    fprintf(out, "tb 0x%" PRIx64 " %" PRIu64 "\n", prof_addr[h] - 1, prof_count[h]);
        }
        fprintf(out, "icount %u %" PRIu64 "\n", measurements++, counter - start_at);
        fflush(out);
    }
    armed = 0;
}

static void on_tb(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    size_t n = qemu_plugin_tb_n_insns(tb);
    qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &counter, n);
    if (profile_n >= 0 && n > 0) {
        uint64_t a0 = qemu_plugin_insn_vaddr(qemu_plugin_tb_get_insn(tb, 0));
        qemu_plugin_register_vcpu_tb_exec_cb(tb, on_tb_exec, QEMU_PLUGIN_CB_NO_REGS,
                                             (void *)(uintptr_t)((a0 << 16) | (n & 0xffff)));
    }
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        uint64_t a = qemu_plugin_insn_vaddr(insn) & ~(uint64_t)1;
        if (a == start_addr)
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_start, QEMU_PLUGIN_CB_NO_REGS, NULL);
        if (a == stop_addr)
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_stop, QEMU_PLUGIN_CB_NO_REGS, NULL);
    }
}

static void at_exit(qemu_plugin_id_t id, void *ud)
{
    (void)id; (void)ud;
    fprintf(out, "icount total %" PRIu64 "\n", counter);
    fflush(out);
    if (out != stderr)
        fclose(out);
}

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id,
                                                               const qemu_info_t *info,
                                                               int argc, char **argv)
{
    (void)info;
    out = stderr;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (strncmp(a, "start=", 6) == 0)
            start_addr = strtoull(a + 6, NULL, 0) & ~(uint64_t)1;
        else if (strncmp(a, "stop=", 5) == 0)
            stop_addr = strtoull(a + 5, NULL, 0) & ~(uint64_t)1;
        else if (strncmp(a, "profile=", 8) == 0)
            profile_n = strtol(a + 8, NULL, 0);
        else if (strncmp(a, "out=", 4) == 0) {
            out = fopen(a + 4, "w");
            if (!out) {
                perror(a + 4);
                return -1;
            }
        } else {
            fprintf(stderr, "icount: unknown argument %s\n", a);
            return -1;
        }
    }
    if (start_addr == UINT64_MAX || stop_addr == UINT64_MAX) {
        fprintf(stderr, "icount: need start=ADDR,stop=ADDR\n");
        return -1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_tb);
    qemu_plugin_register_atexit_cb(id, at_exit, NULL);
    return 0;
}
