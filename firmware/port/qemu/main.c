/* main.c - the emulator port (qemu-system-arm -M netduinoplus2): the application loop
 * of firmware/rfs_app.c driven by a recorded input stream read through semihosting,
 * its output stream written through semihosting.
 *
 *   qemu-system-arm -M netduinoplus2 -nographic -semihosting-config enable=on,target=native \
 *       -kernel qemu.elf -append "IN.rfsr OUT.rfso"
 *
 * The driver loop is rfs_replay_play(), the same code the host program runs, so the two
 * output streams must be identical byte for byte. Exit status 0 on success, 1 on a
 * malformed stream (a message on the semihosting console names the reason).
 */
#include <stdint.h>
#include <string.h>

#include "bench_clock.h"
#include "rfs_app.h"
#include "rfs_mlp.h"
#include "rfs_pathloss.h"
#include "rfs_replay.h"
#include "semihost.h"

static rfs_app_t s_app;
static rfs_replay_player_t s_player;
/* The hardware image's placement: the sample store in the CCM region (here the upper
 * 64 KB of qemu's RAM), the model state with the rest in SRAM. */
static rfs_sample_t s_samples[RFS_APP_MAX_SAMPLES] __attribute__((section(".ccm")));
/* State for the model a CFG record names, sized as the hardware image's (the path-loss
 * model's): it holds the ridge, the MLP and the path-loss model; a stream naming knn or
 * radius stops with "CFG model's state is larger than the image holds". */
#define MODEL_BYTES (sizeof(rfs_pathloss_t) > sizeof(rfs_mlp_t) ? sizeof(rfs_pathloss_t) : sizeof(rfs_mlp_t))
static uint64_t s_model[(MODEL_BYTES + 7u) / 8u];

/* Stack high-water mark: the stack is painted at start and scanned at the end (the
 * figure that sizes the hardware image's stack, docs/FIRMWARE.md), counted from the top
 * of the stack: the depth below the painting's stack pointer plus the start-up's frames
 * above it. */
extern uint32_t _estack;

/* A fault (a stack overflow runs off the bottom of SRAM) ends the run loudly. */
void HardFault_Handler(void);
void HardFault_Handler(void)
{
    rfs_sh_puts("rfseek-qemu: HardFault (stack overflow or bad access)\n");
    rfs_sh_exit(1);
}

/* Output buffering: semihosting calls are slow in the emulator (a trap each). */
typedef struct out_sink {
    int32_t fd;
    uint32_t n;
    int failed;
    uint8_t buf[4096];
} out_sink_t;
static out_sink_t s_out;

static void flush(out_sink_t *o)
{
    if (o->n != 0u && rfs_sh_write(o->fd, o->buf, o->n) != 0) {
        o->failed = 1;
    }
    o->n = 0;
}

static void sink(void *ctx, const uint8_t *p, uint32_t n)
{
    out_sink_t *o = ctx;
    if (o->n + n > sizeof o->buf) {
        flush(o);
    }
    memcpy(o->buf + o->n, p, n);
    o->n += n;
}

static void die(const char *what)
{
    rfs_sh_puts("rfseek-qemu: ");
    rfs_sh_puts(what);
    rfs_sh_puts("\n");
    rfs_sh_exit(1);
}

/* Split "image in out" into its second and third words. */
static int args(char *cmd, char **in, char **out)
{
    char *w[3] = {0, 0, 0};
    unsigned k = 0;
    for (char *p = cmd; *p != '\0' && k < 3u;) {
        while (*p == ' ') {
            *p++ = '\0';
        }
        if (*p == '\0') {
            break;
        }
        w[k++] = p;
        while (*p != '\0' && *p != ' ') {
            p++;
        }
    }
    if (k != 3u) {
        return -1;
    }
    *in = w[1];
    *out = w[2];
    return 0;
}

int main(void)
{
    const uintptr_t sp = rfs_bc_stack_paint();
    static char cmd[256];
    char *in_name, *out_name;
    if (rfs_sh_cmdline(cmd, sizeof cmd) != 0 || args(cmd, &in_name, &out_name) != 0) {
        die("usage: -append \"INPUT.rfsr OUTPUT.rfso\"");
    }
    const int32_t in = rfs_sh_open(in_name, 1u);
    if (in < 0) {
        die("cannot open the input stream");
    }
    s_out.fd = rfs_sh_open(out_name, 5u);
    if (s_out.fd < 0) {
        die("cannot open the output stream");
    }

    static uint8_t buf[2048];
    uint32_t have = 0, pos = 0;
    int32_t got = rfs_sh_read(in, buf, RFS_REPLAY_HEADER_LEN);
    if (got != (int32_t)RFS_REPLAY_HEADER_LEN || rfs_replay_check_header(buf, (uint32_t)got) != 0) {
        die("input: not an rfseek stream (bad header)");
    }
    rfs_app_cfg_t cfg = rfs_app_cfg_default();
    cfg.follow_epoch = true; /* as the STM32 image (rfs_app_cfg_mcu) */
    cfg.samples = s_samples;
    cfg.model_state = s_model;
    cfg.model_state_bytes = (uint32_t)sizeof s_model;
    rfs_replay_player_init(&s_player, &s_app, &cfg, sink, &s_out);

    bool eof = false, ended = false;
    while (!ended) {
        rfs_replay_rec_t rec;
        uint32_t used = 0;
        const rfs_replay_status_t st = rfs_replay_parse(buf + pos, have - pos, &used, &rec);
        if (st == RFS_REPLAY_NEED_MORE) {
            if (eof) {
                if (pos != have) {
                    die("input: truncated record at the end");
                }
                break;
            }
            memmove(buf, buf + pos, have - pos);
            have -= pos;
            pos = 0;
            got = rfs_sh_read(in, buf + have, (uint32_t)sizeof buf - have);
            if (got < 0) {
                die("input: read error");
            }
            eof = got == 0;
            have += (uint32_t)got;
            continue;
        }
        if (st == RFS_REPLAY_BAD) {
            die(rec.error);
        }
        pos += used;
        if (!rfs_replay_play(&s_player, &rec)) {
            die(rfs_replay_err_str(s_player.error));
        }
        ended = rec.type == RFS_REPLAY_END;
    }
    flush(&s_out);
    rfs_sh_close(s_out.fd);
    rfs_sh_close(in);
    if (s_out.failed) {
        die("output: write error");
    }
    rfs_sh_puts("rfseek-qemu: stack used ");
    rfs_bc_put_u64(rfs_bc_stack_depth(sp) + ((uintptr_t)&_estack - sp));
    rfs_sh_puts(" bytes\n");
    rfs_sh_exit(0);
}
