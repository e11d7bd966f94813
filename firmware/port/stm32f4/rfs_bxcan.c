/* rfs_bxcan.c - bxCAN driver (see rfs_bxcan.h; RM0090 chapter 32). */
#include "rfs_bxcan.h"

#include <stdatomic.h>
#include <stddef.h>
#include <string.h>

_Static_assert(offsetof(rfs_bxcan_regs_t, btr) == 0x01Cu, "BTR at 0x01C");
_Static_assert(offsetof(rfs_bxcan_regs_t, tx) == 0x180u, "TX mailboxes at 0x180");
_Static_assert(offsetof(rfs_bxcan_regs_t, rx) == 0x1B0u, "FIFO mailboxes at 0x1B0");
_Static_assert(offsetof(rfs_bxcan_regs_t, fmr) == 0x200u, "FMR at 0x200");
_Static_assert(offsetof(rfs_bxcan_regs_t, fa1r) == 0x21Cu, "FA1R at 0x21C");
_Static_assert(offsetof(rfs_bxcan_regs_t, filter) == 0x240u, "filter banks at 0x240");
_Static_assert(sizeof(rfs_bxcan_regs_t) == 0x320u, "28 filter banks end at 0x320");

/* Filter banks used: bank 0 -> FIFO 0, bank 1 -> FIFO 1 (CAN1 owns banks 0..13). */
#define BANK_FIFO0 0u
#define BANK_FIFO1 1u

rfs_bxcan_cfg_t rfs_bxcan_cfg_default(void)
{
    rfs_bxcan_cfg_t c;
    memset(&c, 0, sizeof c);
    c.pclk_hz = 42000000u;
    c.bitrate = 500000u;
    c.ts1_tq = 11u;
    c.ts2_tq = 2u;
    c.sjw_tq = 1u;
    c.fifo0_ids[0] = RFS_CAN_ID_POSE_XY;
    c.fifo0_ids[1] = RFS_CAN_ID_POSE_TH;
    c.fifo0_ids[2] = RFS_CAN_ID_CONFIG; /* the operator's, before the mission */
    c.n_fifo0 = 3u;
    c.fifo1_ids[0] = RFS_CAN_ID_RSSI;
    c.fifo1_ids[1] = RFS_CAN_ID_RX_STATUS; /* the radio module's heartbeat */
    c.n_fifo1 = 2u;
    c.max_polls = 100000u;
    return c;
}

int rfs_bxcan_btr(const rfs_bxcan_cfg_t *cfg, uint32_t *btr)
{
    if (cfg->ts1_tq < 1u || cfg->ts1_tq > 16u || cfg->ts2_tq < 1u || cfg->ts2_tq > 8u ||
        cfg->sjw_tq < 1u || cfg->sjw_tq > 4u || cfg->sjw_tq > cfg->ts2_tq || cfg->bitrate == 0u) {
        return -1;
    }
    /* RM0090 32.7.7: NominalBitTime = tq * (1 + TS1 + TS2), tq = (BRP + 1) * tPCLK. */
    const uint32_t tq_per_bit = 1u + cfg->ts1_tq + cfg->ts2_tq;
    const uint32_t div = cfg->bitrate * tq_per_bit;
    if (div == 0u || cfg->pclk_hz % div != 0u) {
        return -1;
    }
    const uint32_t brp = cfg->pclk_hz / div;
    if (brp < 1u || brp > 1024u) {
        return -1;
    }
    *btr = (brp - 1u) | ((uint32_t)(cfg->ts1_tq - 1u) << 16) |
           ((uint32_t)(cfg->ts2_tq - 1u) << 20) | ((uint32_t)(cfg->sjw_tq - 1u) << 24) |
           (cfg->loopback ? (1u << 30) : 0u);
    return 0;
}

/* Wait until (reg & mask) == want, at most max_polls reads. */
static int wait_bits(rfs_bxcan_t *d, volatile uint32_t *reg, uint32_t mask, uint32_t want)
{
    for (uint32_t i = 0; i < d->cfg.max_polls; i++) {
        if ((*reg & mask) == want) {
            return 0;
        }
        if (d->poll_hook != NULL) {
            d->poll_hook(d->poll_ctx);
        }
    }
    return ((*reg & mask) == want) ? 0 : -1;
}

/* Two 16-bit list entries in one filter register: STID[10:0] in bits 15..5 of each
 * half, RTR = IDE = 0 (RM0090 figure 342). */
static uint32_t list_pair(uint16_t a, uint16_t b)
{
    return ((uint32_t)(a & 0x7FFu) << 5) | ((uint32_t)(b & 0x7FFu) << 21);
}

static void set_bank(rfs_bxcan_regs_t *r, uint32_t bank, const uint16_t *ids, uint8_t n,
                     bool fifo1)
{
    const uint32_t bit = 1u << bank;
    r->fa1r &= ~bit;
    if (n == 0u) {
        return;
    }
    uint16_t e[4];
    for (unsigned i = 0; i < 4u; i++) {
        e[i] = ids[i < n ? i : 0u]; /* unused slots repeat the first id */
    }
    r->fm1r |= bit;  /* identifier list mode */
    r->fs1r &= ~bit; /* dual 16-bit scale */
    if (fifo1) {
        r->ffa1r |= bit;
    } else {
        r->ffa1r &= ~bit;
    }
    r->filter[bank].fr1 = list_pair(e[0], e[1]);
    r->filter[bank].fr2 = list_pair(e[2], e[3]);
    r->fa1r |= bit;
}

int rfs_bxcan_init(rfs_bxcan_t *d, rfs_bxcan_regs_t *regs, const rfs_bxcan_cfg_t *cfg,
                   void (*poll_hook)(void *ctx), void *poll_ctx)
{
    uint32_t btr;
    if (d == NULL || regs == NULL || cfg == NULL || cfg->n_fifo0 > RFS_BXCAN_MAX_IDS ||
        cfg->n_fifo1 > RFS_BXCAN_MAX_IDS || cfg->max_polls == 0u ||
        rfs_bxcan_btr(cfg, &btr) != 0) {
        return -1;
    }
    for (unsigned i = 0; i < cfg->n_fifo0; i++) {
        if (cfg->fifo0_ids[i] > RFS_CAN_ID_MAX) {
            return -1;
        }
    }
    for (unsigned i = 0; i < cfg->n_fifo1; i++) {
        if (cfg->fifo1_ids[i] > RFS_CAN_ID_MAX) {
            return -1;
        }
    }
    memset(d, 0, sizeof *d);
    d->r = regs;
    d->cfg = *cfg;
    d->poll_hook = poll_hook;
    d->poll_ctx = poll_ctx;

    /* RM0090 32.4.1: leave sleep, request initialisation, wait for INAK = 1, SLAK = 0. */
    regs->mcr = (regs->mcr & ~RFS_BXCAN_MCR_SLEEP) | RFS_BXCAN_MCR_INRQ;
    if (wait_bits(d, &regs->msr, RFS_BXCAN_MSR_INAK | RFS_BXCAN_MSR_SLAK,
                  RFS_BXCAN_MSR_INAK) != 0) {
        return -1;
    }
    /* Automatic bus-off recovery, transmit in request order, keep newest on overrun
     * off (RFLM = 0: a full FIFO overwrites the last frame; counted as FOVR), retransmit
     * on error (NART = 0), no time-triggered mode, frozen in debug (DBF). */
    regs->mcr = RFS_BXCAN_MCR_INRQ | RFS_BXCAN_MCR_ABOM | RFS_BXCAN_MCR_TXFP |
                RFS_BXCAN_MCR_DBF;
    regs->btr = btr;
    /* Interrupts on a pending frame in either FIFO (RM0090 32.9.2, CAN_IER), or none. */
    regs->ier = cfg->rx_irq ? (RFS_BXCAN_IER_FMPIE0 | RFS_BXCAN_IER_FMPIE1) : 0u;

    /* RM0090 32.7.4: filters are written in filter initialisation mode. */
    regs->fmr |= RFS_BXCAN_FMR_FINIT;
    set_bank(regs, BANK_FIFO0, cfg->fifo0_ids, cfg->n_fifo0, false);
    set_bank(regs, BANK_FIFO1, cfg->fifo1_ids, cfg->n_fifo1, true);
    regs->fmr &= ~RFS_BXCAN_FMR_FINIT;

    regs->mcr &= ~RFS_BXCAN_MCR_INRQ;
    if (wait_bits(d, &regs->msr, RFS_BXCAN_MSR_INAK, 0u) != 0) {
        return -1;
    }
    return 0;
}

/* Let a host test's fake hardware react to a write (a no-op on hardware, where the
 * controller reacts by itself). */
static void hw_sync(rfs_bxcan_t *d)
{
    if (d->poll_hook != NULL) {
        d->poll_hook(d->poll_ctx);
    }
}

/* Any id: pending_abort() takes every pending mailbox. */
#define ANY_ID UINT32_MAX

/* Abort the transmit requests tsr shows pending (mailbox not empty), only those of `id`
 * unless ANY_ID; *n counts them. Returns whether any was aborted. */
static bool pending_abort(rfs_bxcan_regs_t *r, uint32_t tsr, uint32_t id, uint32_t *n)
{
    uint32_t abort = 0u;
    for (unsigned i = 0; i < 3u; i++) {
        if ((tsr & RFS_BXCAN_TSR_TME(i)) == 0u &&
            (id == ANY_ID || (r->tx[i].tir >> RFS_BXCAN_STID_SHIFT) == id)) {
            abort |= RFS_BXCAN_TSR_ABRQ(i);
            (*n)++;
        }
    }
    if (abort != 0u) {
        r->tsr = abort; /* ABRQx are rs: writing 0 elsewhere has no effect */
    }
    return abort != 0u;
}

/* Fill an empty transmit mailbox with f and request its transmission. */
static void mailbox_write(rfs_bxcan_txmb_t *m, const rfs_can_frame_t *f)
{
    m->tir = f->id << RFS_BXCAN_STID_SHIFT; /* standard id, data frame, TXRQ clear */
    m->tdtr = f->dlc;
    m->tdlr = (uint32_t)f->data[0] | ((uint32_t)f->data[1] << 8) |
              ((uint32_t)f->data[2] << 16) | ((uint32_t)f->data[3] << 24);
    m->tdhr = (uint32_t)f->data[4] | ((uint32_t)f->data[5] << 8) |
              ((uint32_t)f->data[6] << 16) | ((uint32_t)f->data[7] << 24);
    m->tir |= RFS_BXCAN_TIR_TXRQ;
}

int rfs_bxcan_send(rfs_bxcan_t *d, const rfs_can_frame_t *f)
{
    rfs_bxcan_regs_t *r = d->r;
    if (d->bus_off || (r->esr & RFS_BXCAN_ESR_BOFF) != 0u) {
        d->tx_refused_bus_off++;
        return -1;
    }
    if (f->id > RFS_CAN_ID_MAX || f->dlc > 8u) {
        d->tx_no_mailbox++;
        return -1;
    }
    /* The frames sent are periodic states (WHEEL_CMD, STATUS): a newer one supersedes a
     * request of its id still pending (held by a bus nobody acknowledges, or lost
     * arbitration), which would otherwise go out late, before it, when the bus returns.
     * ABRQ takes a pending mailbox back at once, one in transmission when that fails. */
    uint32_t tsr = r->tsr;
    if (pending_abort(r, tsr, f->id, &d->tx_superseded)) {
        hw_sync(d);
        tsr = r->tsr;
    }
    unsigned mb = 3u;
    for (unsigned i = 0; i < 3u; i++) {
        if ((tsr & RFS_BXCAN_TSR_TME(i)) != 0u) {
            mb = i;
            break;
        }
    }
    if (mb == 3u) {
        d->tx_no_mailbox++;
        return -1;
    }
    mailbox_write(&r->tx[mb], f);
    d->tx_queued++;
    return 0;
}

int rfs_bxcan_fault_send(rfs_bxcan_regs_t *r, const rfs_can_frame_t *f, uint32_t max_polls,
                         void (*poll_hook)(void *ctx), void *poll_ctx)
{
    uint32_t aborted = 0u;
    (void)pending_abort(r, r->tsr, ANY_ID, &aborted);
    for (uint32_t n = 0; n < max_polls && f->id <= RFS_CAN_ID_MAX && f->dlc <= 8u; n++) {
        if (poll_hook != NULL) {
            poll_hook(poll_ctx);
        }
        const uint32_t t = r->tsr;
        for (unsigned i = 0; i < 3u; i++) {
            if ((t & RFS_BXCAN_TSR_TME(i)) != 0u) {
                mailbox_write(&r->tx[i], f);
                return 0;
            }
        }
    }
    return -1;
}

/* Take the next frame FIFO q holds into *f, releasing its mailbox (counting an overrun
 * first, and dropping frames the driver cannot represent); false when it holds none. */
static bool fifo_take(rfs_bxcan_t *d, unsigned q, rfs_can_frame_t *f)
{
    rfs_bxcan_regs_t *r = d->r;
    volatile uint32_t *rfr = q == 0u ? &r->rf0r : &r->rf1r;
    if ((*rfr & RFS_BXCAN_RFR_FOVR) != 0u) {
        d->rx_overruns++;
        *rfr = RFS_BXCAN_RFR_FOVR; /* rc_w1: write 1 to clear */
        hw_sync(d);
    }
    while ((*rfr & RFS_BXCAN_RFR_FMP_MASK) != 0u) {
        const rfs_bxcan_rxmb_t *m = &r->rx[q];
        const uint32_t rir = m->rir;
        const uint32_t rdtr = m->rdtr;
        const uint32_t lo = m->rdlr;
        const uint32_t hi = m->rdhr;
        *rfr = RFS_BXCAN_RFR_RFOM; /* release the output mailbox */
        hw_sync(d);
        /* RFOM reads 1 until the hardware has moved the next frame in (RM0090 32.9.2, CAN_RFxR):
         * read FMP again only then, or the same frame is read twice. */
        (void)wait_bits(d, rfr, RFS_BXCAN_RFR_RFOM, 0u);
        const uint8_t dlc = (uint8_t)(rdtr & 0xFu);
        if ((rir & (RFS_BXCAN_TIR_IDE | RFS_BXCAN_TIR_RTR)) != 0u || dlc > 8u) {
            d->rx_bad++;
            continue;
        }
        memset(f, 0, sizeof *f);
        f->id = rir >> RFS_BXCAN_STID_SHIFT;
        f->dlc = dlc;
        for (unsigned i = 0; i < 4u; i++) {
            f->data[i] = (uint8_t)(lo >> (8u * i));
            f->data[4u + i] = (uint8_t)(hi >> (8u * i));
        }
        for (unsigned i = dlc; i < 8u; i++) {
            f->data[i] = 0u;
        }
        d->rx_frames++;
        return true;
    }
    return false;
}

bool rfs_bxcan_recv(rfs_bxcan_t *d, rfs_can_frame_t *f)
{
    if (d->cfg.rx_irq) {
        const uint32_t tail = d->rxq_tail;
        if (d->rxq_head == tail) {
            return false;
        }
        /* The frame was written before the interrupt published head. */
        atomic_signal_fence(memory_order_acquire);
        *f = d->rxq[tail % RFS_BXCAN_RXQ];
        atomic_signal_fence(memory_order_release); /* read before its slot is freed */
        d->rxq_tail = tail + 1u;
        return true;
    }
    return fifo_take(d, 0u, f) || fifo_take(d, 1u, f);
}

void rfs_bxcan_isr(rfs_bxcan_t *d, unsigned fifo)
{
    rfs_can_frame_t f;
    while (fifo_take(d, fifo != 0u ? 1u : 0u, &f)) {
        const uint32_t head = d->rxq_head;
        if (head - d->rxq_tail >= RFS_BXCAN_RXQ) {
            d->rx_queue_full++; /* released all the same: the interrupt must not stay pending */
            continue;
        }
        atomic_signal_fence(memory_order_acquire); /* the slot was read before it was freed */
        d->rxq[head % RFS_BXCAN_RXQ] = f;
        atomic_signal_fence(memory_order_release); /* the frame before head moves */
        d->rxq_head = head + 1u;
    }
}

bool rfs_bxcan_poll(rfs_bxcan_t *d)
{
    rfs_bxcan_regs_t *r = d->r;
    const bool off = (r->esr & RFS_BXCAN_ESR_BOFF) != 0u;
    if (off && !d->bus_off) {
        d->bus_off_events++;
        (void)pending_abort(r, r->tsr, ANY_ID, &d->tx_aborted);
    }
    d->bus_off = off;
    return off;
}
