/* test_bxcan.c - the bxCAN driver against a fake register block.
 *
 * No emulator models bxCAN, so the test plays the hardware: a plain rfs_bxcan_regs_t in
 * memory, and a fake that acknowledges mode requests (INRQ -> INAK) and releases FIFO
 * mailboxes (RFOM) the way RM0090 chapter 32 describes. Expected register values are
 * worked out by hand from the reference manual's bit layouts (comments give the sums),
 * never taken from the driver.
 */
#include "rfs_test.h"

#include <string.h>

#include "port/stm32f4/rfs_bxcan.h"

typedef struct fake_frame {
    uint32_t rir, rdtr, rdlr, rdhr;
} fake_frame_t;

typedef struct fake_hw {
    rfs_bxcan_regs_t r;
    fake_frame_t q[2][8]; /* frames waiting behind each FIFO's output mailbox */
    unsigned nq[2];
    uint32_t rfr_last[2]; /* what the fake last put in RF0R / RF1R */
    bool fovr[2];         /* overrun flag (rc_w1) */
    unsigned released[2]; /* RFOM releases seen */
    unsigned release_ticks; /* polls a mailbox release takes, RFOM reading 1 meanwhile */
    unsigned releasing[2];  /* polls left of a release under way */
    bool ack_modes;       /* false: a dead controller that never acknowledges */
    bool aborts;          /* TSR modelled: an ABRQ write empties its (pending) mailbox */
    uint32_t tme;         /* ... the TME bits then (TSR's others are not memory) */
    unsigned sending;     /* ... but not of these mailboxes (bit i): in transmission */
    unsigned hook_calls;
} fake_hw_t;

/* Load the head of FIFO f into its output mailbox; RFxR = FMP | FULL | FOVR. */
static void fifo_load(fake_hw_t *hw, unsigned f)
{
    volatile uint32_t *rfr = f == 0 ? &hw->r.rf0r : &hw->r.rf1r;
    const uint32_t keep = (hw->fovr[f] ? RFS_BXCAN_RFR_FOVR : 0u) |
                          (hw->nq[f] >= 3 ? RFS_BXCAN_RFR_FULL : 0u);
    if (hw->nq[f] > 0) {
        hw->r.rx[f].rir = hw->q[f][0].rir;
        hw->r.rx[f].rdtr = hw->q[f][0].rdtr;
        hw->r.rx[f].rdlr = hw->q[f][0].rdlr;
        hw->r.rx[f].rdhr = hw->q[f][0].rdhr;
    }
    *rfr = keep | (hw->nq[f] > 3 ? 3u : hw->nq[f]);
    hw->rfr_last[f] = *rfr;
}

/* What the hardware does between two accesses of the driver. */
static void fake_tick(void *ctx)
{
    fake_hw_t *hw = ctx;
    hw->hook_calls++;
    if (hw->ack_modes) {
        if (hw->r.mcr & RFS_BXCAN_MCR_INRQ) {
            hw->r.msr = (hw->r.msr | RFS_BXCAN_MSR_INAK) & ~RFS_BXCAN_MSR_SLAK;
        } else {
            hw->r.msr &= ~RFS_BXCAN_MSR_INAK;
        }
    }
    if (hw->aborts) {
        for (unsigned i = 0; i < 3u; i++) {
            if ((hw->r.tsr & RFS_BXCAN_TSR_ABRQ(i)) != 0u && (hw->sending & (1u << i)) == 0u) {
                hw->tme |= RFS_BXCAN_TSR_TME(i); /* RM0090 32.9.3: TME set once aborted */
            }
        }
        hw->r.tsr = hw->tme;
    }
    /* A value in RFxR that differs from what the fake left there was written by the
     * driver: RFOM (rs) releases the mailbox, FOVR (rc_w1) clears the overrun flag. */
    for (unsigned f = 0; f < 2; f++) {
        volatile uint32_t *rfr = f == 0 ? &hw->r.rf0r : &hw->r.rf1r;
        const uint32_t w = *rfr;
        if (hw->releasing[f] > 0 && --hw->releasing[f] > 0) {
            continue; /* still releasing: FMP and the mailbox unchanged, RFOM set */
        }
        if (w == hw->rfr_last[f] && (w & RFS_BXCAN_RFR_RFOM) == 0u) {
            continue;
        }
        if ((w & RFS_BXCAN_RFR_FOVR) != 0u) {
            hw->fovr[f] = false;
        }
        if ((w & RFS_BXCAN_RFR_RFOM) != 0u && hw->nq[f] > 0) {
            if (w != hw->rfr_last[f] && hw->release_ticks > 0) {
                /* The write left RFOM set; FMP (read-only) keeps its count meanwhile. */
                hw->releasing[f] = hw->release_ticks;
                *rfr = hw->rfr_last[f] | RFS_BXCAN_RFR_RFOM;
                hw->rfr_last[f] = *rfr;
                continue;
            }
            memmove(&hw->q[f][0], &hw->q[f][1], sizeof hw->q[f][0] * 7);
            hw->nq[f]--;
            hw->released[f]++;
        }
        fifo_load(hw, f);
    }
}

static void push_rx(fake_hw_t *hw, unsigned f, uint32_t rir, uint8_t dlc, uint32_t lo,
                    uint32_t hi)
{
    hw->q[f][hw->nq[f]++] = (fake_frame_t){rir, dlc, lo, hi};
    fifo_load(hw, f);
}

static int setup(void **state)
{
    static fake_hw_t hw;
    static rfs_bxcan_t d;
    memset(&hw, 0, sizeof hw);
    memset(&d, 0, sizeof d);
    hw.r.mcr = 0x00010002u; /* reset value: SLEEP | DBF (RM0090 32.9.2) */
    hw.r.msr = 0x00000C02u; /* reset value: SLAK */
    hw.r.tsr = 0x1C000000u; /* three empty mailboxes: TME0..2 */
    hw.r.fmr = 0x2A1C0E01u; /* reset value: FINIT, CAN2SB = 14 */
    hw.ack_modes = true;
    static void *pair[2];
    pair[0] = &hw;
    pair[1] = &d;
    *state = pair;
    return 0;
}

static void test_btr_from_the_manual(void **state)
{
    (void)state;
    /* 42 MHz / (500 kbit/s * 14 tq) = 6 -> BRP field 5; TS1 11 -> 10; TS2 2 -> 1; SJW 1 -> 0:
     * 5 | 10 << 16 | 1 << 20 | 0 << 24 = 0x001A0005. */
    rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    uint32_t btr = 0;
    assert_int_equal(rfs_bxcan_btr(&c, &btr), 0);
    assert_int_equal(btr, 0x001A0005u);
    /* 1 Mbit/s at 42 MHz with 1 + 11 + 2 = 14 tq: 42e6 / 14e6 = 3 -> BRP 2: 0x001A0002. */
    c.bitrate = 1000000u;
    assert_int_equal(rfs_bxcan_btr(&c, &btr), 0);
    assert_int_equal(btr, 0x001A0002u);
    /* 42e6 / (300e3 * 14) = 10: exact, BRP 9; 42e6 / (333e3 * 14) is not an integer. */
    c.bitrate = 300000u;
    assert_int_equal(rfs_bxcan_btr(&c, &btr), 0);
    assert_int_equal(btr & 0x3FFu, 9u);
    c.bitrate = 333000u;
    assert_int_equal(rfs_bxcan_btr(&c, &btr), -1);
    c = rfs_bxcan_cfg_default();
    c.ts2_tq = 9u; /* TS2 is 3 bits: 1..8 tq */
    assert_int_equal(rfs_bxcan_btr(&c, &btr), -1);
}

static void test_init_programs_mode_timing_and_filters(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    const rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();

    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);

    /* Normal mode: INRQ and SLEEP clear; ABOM (bit 6) | TXFP (bit 2) | DBF (bit 16). */
    assert_int_equal(hw->r.mcr, 0x00010044u);
    assert_int_equal(hw->r.msr & RFS_BXCAN_MSR_INAK, 0u);
    assert_int_equal(hw->r.btr, 0x001A0005u);
    /* Filters out of init mode, CAN2SB (bits 8..13) untouched: 0x2A1C0E00. */
    assert_int_equal(hw->r.fmr, 0x2A1C0E00u);
    /* Bank 0: list mode, 16-bit, FIFO 0: 0x110 << 5 = 0x2200, 0x111 << 5 = 0x2220,
     * 0x130 << 5 = 0x2600 (CONFIG); slot 3 repeats 0x110. Bank 1: FIFO 1, 0x120 << 5 = 0x2400, 0x121 << 5 = 0x2420
     * (the receiver heartbeat), slots 2, 3 repeat 0x120. */
    assert_int_equal(hw->r.fm1r, 0x3u);
    assert_int_equal(hw->r.fs1r, 0x0u);
    assert_int_equal(hw->r.ffa1r, 0x2u);
    assert_int_equal(hw->r.fa1r, 0x3u);
    assert_int_equal(hw->r.filter[0].fr1, 0x22202200u);
    assert_int_equal(hw->r.filter[0].fr2, 0x22002600u);
    assert_int_equal(hw->r.filter[1].fr1, 0x24202400u);
    assert_int_equal(hw->r.filter[1].fr2, 0x24002400u);
}

static void test_init_fails_when_the_hardware_never_acknowledges(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    c.max_polls = 50u;
    hw->ack_modes = false;

    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), -1);
    assert_int_equal(hw->hook_calls, 50u);
    c.n_fifo0 = 5u;
    hw->ack_modes = true;
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), -1);
}

static void test_send_fills_free_mailboxes_in_order(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    const rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    const rfs_can_frame_t f = {0x100u, 6u, {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0, 0}};

    assert_int_equal(rfs_bxcan_send(d, &f), 0);
    /* STID 0x100 << 21 = 0x20000000, plus TXRQ. Bytes little-endian per register. */
    assert_int_equal(hw->r.tx[0].tir, 0x20000001u);
    assert_int_equal(hw->r.tx[0].tdtr, 6u);
    assert_int_equal(hw->r.tx[0].tdlr, 0x44332211u);
    assert_int_equal(hw->r.tx[0].tdhr, 0x00006655u);

    hw->r.tsr = 0x18000000u; /* mailbox 0 busy: TME1, TME2 */
    const rfs_can_frame_t g = {0x180u, 8u, {1, 2, 3, 4, 5, 6, 7, 8}};
    assert_int_equal(rfs_bxcan_send(d, &g), 0);
    assert_int_equal(hw->r.tx[1].tir, (0x180u << 21) | 1u);
    assert_int_equal(hw->r.tx[1].tdhr, 0x08070605u);

    hw->r.tsr = 0x00000000u; /* all three busy */
    assert_int_equal(rfs_bxcan_send(d, &f), -1);
    assert_int_equal(d->tx_no_mailbox, 1u);
    assert_int_equal(d->tx_queued, 2u);
}

/* A wheel command still pending (no node acknowledges, or it keeps losing arbitration)
 * must not go out after the bus returns: the next one of its id takes its place. */
static void test_send_supersedes_a_pending_frame_of_its_id(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    const rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    const rfs_can_frame_t old_cmd = {0x100u, 6u, {0x10, 0xF4, 0x01, 0xF4, 0x01, 0x00, 0, 0}};
    const rfs_can_frame_t status = {0x180u, 8u, {1, 2, 3, 4, 5, 6, 7, 8}};
    const rfs_can_frame_t stop = {0x100u, 6u, {0x11, 0, 0, 0, 0, 0x00, 0, 0}};
    assert_int_equal(rfs_bxcan_send(d, &old_cmd), 0); /* mailbox 0 */
    hw->r.tsr = 0x18000000u;                            /* TME1, TME2: mailbox 0 pending */
    assert_int_equal(rfs_bxcan_send(d, &status), 0);    /* mailbox 1 */
    hw->aborts = true;
    hw->tme = 0x10000000u; /* TME2: mailboxes 0 and 1 pending */
    hw->r.tsr = hw->tme;

    assert_int_equal(rfs_bxcan_send(d, &stop), 0);

    /* ABRQ0 (bit 7) aborted the old command; the new one took the freed mailbox 0:
     * STID 0x100 << 21 | TXRQ, byte 0 = 0x11. The status (another id) still pending. */
    assert_int_equal(hw->tme & 0x04000000u, 0x04000000u);
    assert_int_equal(d->tx_superseded, 1u);
    assert_int_equal(hw->r.tx[0].tir, 0x20000001u);
    assert_int_equal(hw->r.tx[0].tdlr, 0x00000011u);
    assert_int_equal(hw->r.tx[1].tir, (0x180u << 21) | 1u);
    assert_int_equal(d->tx_queued, 3u);
}

/* The request of its id is in transmission: RM0090 32.7.1, the abort then waits for the
 * transmission's end (the frame may still go out, before the new one). The new frame goes
 * to an empty mailbox, never to the one being sent. */
static void test_send_leaves_a_mailbox_in_transmission_alone(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    const rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    const rfs_can_frame_t stop = {0x100u, 6u, {0x11, 0, 0, 0, 0, 0x00, 0, 0}};
    hw->r.tx[0].tir = (0x100u << 21) | 1u; /* the old command, in transmission */
    hw->r.tx[0].tdlr = 0x01F4F410u;
    hw->r.tx[1].tir = (0x180u << 21) | 1u; /* a status, pending */
    hw->aborts = true;
    hw->sending = 1u;
    hw->tme = 0x10000000u; /* TME2 */
    hw->r.tsr = hw->tme;

    assert_int_equal(rfs_bxcan_send(d, &stop), 0);

    assert_int_equal(hw->tme, 0x10000000u);  /* mailbox 0 still busy after ABRQ0 */
    assert_int_equal(hw->r.tx[0].tdlr, 0x01F4F410u);
    assert_int_equal(hw->r.tx[2].tir, 0x20000001u);
    assert_int_equal(hw->r.tx[2].tdlr, 0x00000011u);
    assert_int_equal(hw->r.tx[1].tir, (0x180u << 21) | 1u);
}

/* A fault handler's stop: every pending request aborted (ABRQ0..2: bits 7, 15, 23), the
 * frame in the first mailbox that empties; none empties: -1, nothing written. */
static void test_fault_send_aborts_pending_requests_and_sends(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    const rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    const rfs_can_frame_t stop = {0x100u, 6u, {0x13, 0, 0, 0, 0, 0x5A, 0, 0}};
    hw->r.tx[0].tir = (0x100u << 21) | 1u; /* three pending requests */
    hw->r.tx[1].tir = (0x180u << 21) | 1u;
    hw->r.tx[2].tir = (0x100u << 21) | 1u;
    hw->r.tsr = 0u;

    assert_int_equal(rfs_bxcan_fault_send(&hw->r, &stop, 10u, NULL, NULL), -1);
    assert_int_equal(hw->r.tsr, 0x00808080u); /* ABRQ0..2 written; no mailbox emptied */
    assert_int_equal(hw->r.tx[0].tdlr, 0u);

    hw->aborts = true;
    hw->tme = 0u;
    hw->r.tsr = 0u;
    assert_int_equal(rfs_bxcan_fault_send(&hw->r, &stop, 10u, fake_tick, hw), 0);
    assert_int_equal(hw->tme, 0x1C000000u); /* all three aborted */
    assert_int_equal(hw->r.tx[0].tir, 0x20000001u);
    assert_int_equal(hw->r.tx[0].tdtr, 6u);
    assert_int_equal(hw->r.tx[0].tdlr, 0x00000013u);
    assert_int_equal(hw->r.tx[0].tdhr, 0x00005A00u);
}

static void test_recv_reads_fifo0_first_and_releases_each_mailbox(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    const rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    push_rx(hw, 1, 0x120u << 21, 8u, 0x04030201u, 0x08070605u);
    push_rx(hw, 0, 0x110u << 21, 8u, 0xA3A2A1A0u, 0xA7A6A5A4u);
    push_rx(hw, 0, 0x111u << 21, 3u, 0x00B2B1B0u, 0x0u);
    rfs_can_frame_t f;

    assert_true(rfs_bxcan_recv(d, &f));
    assert_int_equal(hw->released[0], 1u);
    assert_int_equal(f.id, 0x110u);
    assert_int_equal(f.dlc, 8u);
    assert_int_equal(f.data[0], 0xA0);
    assert_int_equal(f.data[7], 0xA7);
    assert_true(rfs_bxcan_recv(d, &f));
    assert_int_equal(f.id, 0x111u);
    assert_int_equal(f.dlc, 3u);
    assert_int_equal(f.data[2], 0xB2);
    assert_int_equal(f.data[3], 0x00); /* bytes past the DLC are zero */
    assert_true(rfs_bxcan_recv(d, &f));
    assert_int_equal(f.id, 0x120u);
    assert_int_equal(hw->released[1], 1u);
    assert_false(rfs_bxcan_recv(d, &f));
    assert_int_equal(d->rx_frames, 3u);
    assert_int_equal(hw->nq[0] + hw->nq[1], 0u);
}

static void test_recv_drops_extended_and_remote_frames_and_counts_overruns(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    const rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    push_rx(hw, 0, (0x110u << 21) | RFS_BXCAN_TIR_IDE, 8u, 0, 0); /* extended id */
    push_rx(hw, 0, (0x110u << 21) | RFS_BXCAN_TIR_RTR, 0u, 0, 0); /* remote frame */
    push_rx(hw, 0, 0x111u << 21, 8u, 0x01u, 0);
    hw->fovr[0] = true;
    fifo_load(hw, 0);
    rfs_can_frame_t f;

    assert_true(rfs_bxcan_recv(d, &f));
    assert_int_equal(f.id, 0x111u);
    assert_int_equal(f.data[0], 0x01);
    assert_int_equal(d->rx_bad, 2u);
    assert_int_equal(d->rx_overruns, 1u);
    assert_false(hw->fovr[0]);
    assert_int_equal(hw->released[0], 3u);
    assert_false(rfs_bxcan_recv(d, &f));
}

static void test_bus_off_aborts_pending_mailboxes_and_refuses_sends(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    const rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    const rfs_can_frame_t f = {0x100u, 6u, {0}};
    hw->r.tsr = 0x14000000u;              /* mailbox 1 holds a pending request */
    hw->r.esr = RFS_BXCAN_ESR_BOFF | (255u << 16); /* TEC 255: bus-off */

    assert_true(rfs_bxcan_poll(d));
    assert_int_equal(hw->r.tsr, 1u << 15); /* ABRQ1 */
    assert_int_equal(d->tx_aborted, 1u);
    assert_int_equal(d->bus_off_events, 1u);
    assert_int_equal(rfs_bxcan_send(d, &f), -1);
    assert_int_equal(d->tx_refused_bus_off, 1u);
    assert_true(rfs_bxcan_poll(d)); /* still off: not a second event */
    assert_int_equal(d->bus_off_events, 1u);

    hw->r.esr = 0u; /* ABOM recovered after 128 x 11 recessive bits */
    hw->r.tsr = 0x1C000000u;
    assert_false(rfs_bxcan_poll(d));
    assert_int_equal(rfs_bxcan_send(d, &f), 0);
}

/* A frame whose identifier and first data word carry k. */
static void push_k(fake_hw_t *hw, unsigned f, uint32_t k)
{
    push_rx(hw, f, (0x100u + k) << 21, 8u, k, ~k);
}

static void test_rx_irq_enables_the_fifo_interrupts(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    hw->r.ier = 0xFFFFFFFFu;
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    assert_int_equal(hw->r.ier, 0u); /* polled: no interrupt */
    c.rx_irq = true;
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    /* FMPIE0 (bit 1) | FMPIE1 (bit 4) = 0x12 (RM0090 32.9.2, CAN_IER). */
    assert_int_equal(hw->r.ier, 0x12u);
}

static void test_isr_queues_frames_in_arrival_order_beyond_the_fifos(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    c.rx_irq = true;
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    hw->release_ticks = 2u; /* RFOM reads 1 for two polls after each release */
    rfs_can_frame_t f;
    /* While the main loop is away: 7 bursts of 3 frames, FIFO 1 then FIFO 0 in turn, each
     * taken by its interrupt: 21 frames, 7 times what one FIFO holds. */
    for (uint32_t b = 0; b < 7u; b++) {
        const unsigned fifo = (b % 2u == 0u) ? 1u : 0u;
        for (uint32_t i = 0; i < 3u; i++) {
            push_k(hw, fifo, 3u * b + i);
        }
        rfs_bxcan_isr(d, fifo);
        assert_int_equal(hw->nq[fifo], 0u);
    }
    assert_int_equal(hw->released[0] + hw->released[1], 21u);
    for (uint32_t k = 0; k < 21u; k++) {
        assert_true(rfs_bxcan_recv(d, &f));
        assert_int_equal(f.id, 0x100u + k);
        assert_int_equal(f.dlc, 8u);
        assert_int_equal(f.data[0], k);
        assert_int_equal(f.data[4], 0xFFu - k);
    }
    assert_false(rfs_bxcan_recv(d, &f));
    assert_int_equal(d->rx_frames, 21u);
    assert_int_equal(d->rx_queue_full, 0u);

    /* The main loop never reads the FIFOs itself: a frame no interrupt took stays. */
    push_k(hw, 0, 99u);
    assert_false(rfs_bxcan_recv(d, &f));
    assert_int_equal(hw->nq[0], 1u);
}

static void test_isr_counts_and_releases_frames_a_full_queue_drops(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    c.rx_irq = true;
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    rfs_can_frame_t f;
    uint32_t k = 0;
    /* 36 frames, 12 interrupts: the queue keeps the first 32, drops 4, frees every
     * mailbox (else the interrupt would stay pending). */
    for (uint32_t b = 0; b < 12u; b++) {
        for (uint32_t i = 0; i < 3u; i++) {
            push_k(hw, 1, k++);
        }
        rfs_bxcan_isr(d, 1);
    }
    assert_int_equal(RFS_BXCAN_RXQ, 32u);
    assert_int_equal(hw->released[1], 36u);
    assert_int_equal(hw->nq[1], 0u);
    assert_int_equal(d->rx_queue_full, 4u);
    for (uint32_t j = 0; j < 32u; j++) {
        assert_true(rfs_bxcan_recv(d, &f));
        assert_int_equal(f.id, 0x100u + j);
    }
    assert_false(rfs_bxcan_recv(d, &f));
    /* Past the wrap of the slots: 40 more, taken as they come. */
    for (uint32_t j = 0; j < 40u; j++) {
        push_k(hw, 0, 40u + j);
        rfs_bxcan_isr(d, 0);
        assert_true(rfs_bxcan_recv(d, &f));
        assert_int_equal(f.id, 0x100u + 40u + j);
        assert_int_equal(f.data[0], 40u + j);
    }
    assert_int_equal(d->rx_queue_full, 4u);
    assert_int_equal(d->rxq_head, 72u);
}

static void test_polled_recv_waits_for_each_release(void **state)
{
    fake_hw_t *hw = ((void **)*state)[0];
    rfs_bxcan_t *d = ((void **)*state)[1];
    const rfs_bxcan_cfg_t c = rfs_bxcan_cfg_default();
    assert_int_equal(rfs_bxcan_init(d, &hw->r, &c, fake_tick, hw), 0);
    hw->release_ticks = 3u;
    push_k(hw, 0, 1u);
    push_k(hw, 0, 2u);
    rfs_can_frame_t f;
    assert_true(rfs_bxcan_recv(d, &f));
    assert_int_equal(f.id, 0x101u);
    assert_true(rfs_bxcan_recv(d, &f)); /* the next frame, not the first again */
    assert_int_equal(f.id, 0x102u);
    assert_false(rfs_bxcan_recv(d, &f));
    assert_int_equal(hw->released[0], 2u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_btr_from_the_manual),
        cmocka_unit_test_setup(test_init_programs_mode_timing_and_filters, setup),
        cmocka_unit_test_setup(test_init_fails_when_the_hardware_never_acknowledges, setup),
        cmocka_unit_test_setup(test_send_fills_free_mailboxes_in_order, setup),
        cmocka_unit_test_setup(test_send_supersedes_a_pending_frame_of_its_id, setup),
        cmocka_unit_test_setup(test_send_leaves_a_mailbox_in_transmission_alone, setup),
        cmocka_unit_test_setup(test_fault_send_aborts_pending_requests_and_sends, setup),
        cmocka_unit_test_setup(test_recv_reads_fifo0_first_and_releases_each_mailbox, setup),
        cmocka_unit_test_setup(test_recv_drops_extended_and_remote_frames_and_counts_overruns,
                               setup),
        cmocka_unit_test_setup(test_bus_off_aborts_pending_mailboxes_and_refuses_sends, setup),
        cmocka_unit_test_setup(test_rx_irq_enables_the_fifo_interrupts, setup),
        cmocka_unit_test_setup(test_isr_queues_frames_in_arrival_order_beyond_the_fifos, setup),
        cmocka_unit_test_setup(test_isr_counts_and_releases_frames_a_full_queue_drops, setup),
        cmocka_unit_test_setup(test_polled_recv_waits_for_each_release, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
