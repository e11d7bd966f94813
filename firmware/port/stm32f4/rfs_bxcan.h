/* rfs_bxcan.h - register-level driver for the STM32F4 bxCAN controller (RM0090 rev 19,
 * chapter 32 "Controller area network (bxCAN)").
 *
 * The driver works on a register block passed in (CAN1 at 0x40006400 on hardware, a
 * plain struct in the host tests). It configures the bit timing (BTR), the acceptance
 * filters (16-bit identifier-list banks, inputs split over FIFO 0 and FIFO 1), sends
 * through the three transmit mailboxes in request order (TXFP), receives from FIFO 0
 * then FIFO 1 and releases each mailbox (RFOM), counts FIFO overruns (FOVR), and reports
 * bus-off (ESR BOFF). Reception is polled by the main loop, or (cfg.rx_irq) taken by the
 * FIFO-pending interrupts into a software queue the main loop reads: the hardware holds
 * three frames a FIFO, fewer than arrive while a fit slice runs. Recovery is the hardware's automatic bus-off management (ABOM: 128 x 11
 * recessive bits); on entering bus-off the pending mailboxes are aborted (ABRQ) so a
 * stale wheel command is never sent after recovery; likewise a new frame aborts a pending
 * one of its id (rfs_bxcan_send()).
 *
 * Waiting for the hardware (INAK after INRQ) is bounded by cfg.max_polls; `poll_hook`,
 * NULL on hardware, is called on each wait so a host test can play the hardware's part.
 */
#ifndef RFS_BXCAN_H
#define RFS_BXCAN_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_can.h"

/// One transmit mailbox (RM0090 32.9.3: CAN_TIxR, CAN_TDTxR, CAN_TDLxR, CAN_TDHxR).
typedef struct rfs_bxcan_txmb {
    volatile uint32_t tir;  ///< identifier, IDE, RTR, TXRQ
    volatile uint32_t tdtr; ///< DLC, TGT, time stamp
    volatile uint32_t tdlr; ///< data bytes 0..3
    volatile uint32_t tdhr; ///< data bytes 4..7
} rfs_bxcan_txmb_t;

/// One receive FIFO output mailbox (CAN_RIxR, CAN_RDTxR, CAN_RDLxR, CAN_RDHxR).
typedef struct rfs_bxcan_rxmb {
    volatile uint32_t rir;  ///< identifier, IDE, RTR
    volatile uint32_t rdtr; ///< DLC, filter match index, time stamp
    volatile uint32_t rdlr; ///< data bytes 0..3
    volatile uint32_t rdhr; ///< data bytes 4..7
} rfs_bxcan_rxmb_t;

/// One filter bank (CAN_FiR1, CAN_FiR2).
typedef struct rfs_bxcan_filter {
    volatile uint32_t fr1; ///< 32-bit id / mask, or two 16-bit ids
    volatile uint32_t fr2; ///< second register of the bank
} rfs_bxcan_filter_t;

/// The bxCAN register block (RM0090 table 184, CAN register map).
typedef struct rfs_bxcan_regs {
    volatile uint32_t mcr;            ///< 0x000 master control
    volatile uint32_t msr;            ///< 0x004 master status
    volatile uint32_t tsr;            ///< 0x008 transmit status
    volatile uint32_t rf0r;           ///< 0x00C receive FIFO 0
    volatile uint32_t rf1r;           ///< 0x010 receive FIFO 1
    volatile uint32_t ier;            ///< 0x014 interrupt enable
    volatile uint32_t esr;            ///< 0x018 error status
    volatile uint32_t btr;            ///< 0x01C bit timing
    uint32_t reserved0[88];           ///< 0x020 .. 0x17F
    rfs_bxcan_txmb_t tx[3];           ///< 0x180 transmit mailboxes
    rfs_bxcan_rxmb_t rx[2];           ///< 0x1B0 FIFO 0 and FIFO 1 output mailboxes
    uint32_t reserved1[12];           ///< 0x1D0 .. 0x1FF
    volatile uint32_t fmr;            ///< 0x200 filter master
    volatile uint32_t fm1r;           ///< 0x204 filter mode (1 = identifier list)
    uint32_t reserved2;               ///< 0x208
    volatile uint32_t fs1r;           ///< 0x20C filter scale (1 = single 32-bit)
    uint32_t reserved3;               ///< 0x210
    volatile uint32_t ffa1r;          ///< 0x214 filter FIFO assignment (1 = FIFO 1)
    uint32_t reserved4;               ///< 0x218
    volatile uint32_t fa1r;           ///< 0x21C filter activation
    uint32_t reserved5[8];            ///< 0x220 .. 0x23F
    rfs_bxcan_filter_t filter[28];    ///< 0x240 filter banks 0..27
} rfs_bxcan_regs_t;

/// CAN1 on the STM32F405 (RM0090 table 1).
#define RFS_BXCAN1_BASE 0x40006400u

/* Register bits used (RM0090 32.9.2 - 32.9.5). */
#define RFS_BXCAN_MCR_INRQ (1u << 0)
#define RFS_BXCAN_MCR_SLEEP (1u << 1)
#define RFS_BXCAN_MCR_TXFP (1u << 2)
#define RFS_BXCAN_MCR_RFLM (1u << 3)
#define RFS_BXCAN_MCR_NART (1u << 4)
#define RFS_BXCAN_MCR_AWUM (1u << 5)
#define RFS_BXCAN_MCR_ABOM (1u << 6)
#define RFS_BXCAN_MCR_TTCM (1u << 7)
#define RFS_BXCAN_MCR_RESET (1u << 15)
#define RFS_BXCAN_MCR_DBF (1u << 16)
#define RFS_BXCAN_MSR_INAK (1u << 0)
#define RFS_BXCAN_MSR_SLAK (1u << 1)
#define RFS_BXCAN_TSR_ABRQ(i) (1u << (7u + 8u * (i)))
#define RFS_BXCAN_TSR_RQCP(i) (1u << (8u * (i)))
#define RFS_BXCAN_TSR_TXOK(i) (1u << (1u + 8u * (i)))
#define RFS_BXCAN_TSR_TERR(i) (1u << (3u + 8u * (i)))
#define RFS_BXCAN_TSR_TME(i) (1u << (26u + (i)))
#define RFS_BXCAN_IER_FMPIE0 (1u << 1)
#define RFS_BXCAN_IER_FMPIE1 (1u << 4)
#define RFS_BXCAN_RFR_FMP_MASK 0x3u
#define RFS_BXCAN_RFR_FULL (1u << 3)
#define RFS_BXCAN_RFR_FOVR (1u << 4)
#define RFS_BXCAN_RFR_RFOM (1u << 5)
#define RFS_BXCAN_ESR_EWGF (1u << 0)
#define RFS_BXCAN_ESR_EPVF (1u << 1)
#define RFS_BXCAN_ESR_BOFF (1u << 2)
#define RFS_BXCAN_TIR_TXRQ (1u << 0)
#define RFS_BXCAN_TIR_RTR (1u << 1)
#define RFS_BXCAN_TIR_IDE (1u << 2)
#define RFS_BXCAN_STID_SHIFT 21u
#define RFS_BXCAN_FMR_FINIT (1u << 0)

/// Most identifiers per FIFO (one 16-bit list bank holds four).
#define RFS_BXCAN_MAX_IDS 4u

/// Frames the software receive queue holds (cfg.rx_irq; a power of two): a burst of 32,
/// or about 0.15 s of the inputs (RSSI up to 200 a second, two pose frames at 10 Hz),
/// against the 3 ms at most a control step or fit slice keeps the main loop away.
#define RFS_BXCAN_RXQ 32u

/// Driver configuration.
typedef struct rfs_bxcan_cfg {
    uint32_t pclk_hz;                     ///< APB1 clock feeding the controller, Hz (42 MHz)
    uint32_t bitrate;                     ///< bits per second (500,000)
    uint8_t ts1_tq;                       ///< time segment 1, time quanta, 1..16 (11)
    uint8_t ts2_tq;                       ///< time segment 2, time quanta, 1..8 (2)
    uint8_t sjw_tq;                       ///< resynchronisation jump width, 1..4 (1)
    uint16_t fifo0_ids[RFS_BXCAN_MAX_IDS]; ///< 11-bit ids accepted into FIFO 0
    uint8_t n_fifo0;                      ///< how many (0..4)
    uint16_t fifo1_ids[RFS_BXCAN_MAX_IDS]; ///< 11-bit ids accepted into FIFO 1
    uint8_t n_fifo1;                      ///< how many (0..4)
    bool loopback;                        ///< LBKM: self-test loop back
    bool rx_irq;                          ///< receive in the FIFO-pending interrupts
                                          ///< (rfs_bxcan_isr()) into the software queue;
                                          ///< false: rfs_bxcan_recv() polls the FIFOs
    uint32_t max_polls;                   ///< bound on every wait for the hardware
} rfs_bxcan_cfg_t;

/// Driver state.
typedef struct rfs_bxcan {
    rfs_bxcan_regs_t *r;          ///< the register block
    rfs_bxcan_cfg_t cfg;          ///< configuration copied at init
    void (*poll_hook)(void *ctx); ///< called on each wait poll (host tests); NULL on hardware
    void *poll_ctx;               ///< its argument
    bool bus_off;                 ///< ESR.BOFF at the last rfs_bxcan_poll()
    uint32_t tx_queued;           ///< frames placed in a mailbox
    uint32_t tx_no_mailbox;       ///< frames refused: all three mailboxes busy
    uint32_t tx_refused_bus_off;  ///< frames refused while bus-off
    uint32_t tx_aborted;          ///< mailbox requests aborted on entering bus-off
    uint32_t tx_superseded;       ///< pending requests aborted for a newer frame of their id
    uint32_t rx_frames;           ///< frames read from the FIFOs
    uint32_t rx_overruns;         ///< FIFO overruns seen (a frame was lost)
    uint32_t rx_bad;              ///< frames dropped: extended id, remote frame or DLC > 8
    uint32_t rx_queue_full;       ///< frames dropped: the software queue was full (rx_irq)
    uint32_t bus_off_events;      ///< transitions into bus-off
    /* The software receive queue (rx_irq): written by rfs_bxcan_isr() only, read by
     * rfs_bxcan_recv() only; free-running indices, frame k at rxq[k % RFS_BXCAN_RXQ]. */
    rfs_can_frame_t rxq[RFS_BXCAN_RXQ]; ///< queued frames
    volatile uint32_t rxq_head;   ///< frames queued so far (the interrupt's)
    volatile uint32_t rxq_tail;   ///< frames taken so far (the main loop's)
} rfs_bxcan_t;

/// Defaults: 42 MHz APB1, 500 kbit/s, 1 + 11 + 2 tq (sample point 85.7 %), SJW 1;
/// POSE_XY and POSE_TH into FIFO 0 (their order matters), RSSI and RX_STATUS (the
/// receiver heartbeat) into FIFO 1.
rfs_bxcan_cfg_t rfs_bxcan_cfg_default(void);

/// The BTR value for a configuration: BRP = pclk / (bitrate * (1 + ts1 + ts2)) - 1.
/// Returns 0 with *btr set, or -1 when the bit rate is not reachable exactly.
int rfs_bxcan_btr(const rfs_bxcan_cfg_t *cfg, uint32_t *btr);

/// Leave sleep, enter initialisation mode, program bit timing and filters, leave
/// initialisation mode. Returns 0, or -1 on a bad configuration or when the hardware
/// does not acknowledge a mode change within cfg.max_polls.
int rfs_bxcan_init(rfs_bxcan_t *d, rfs_bxcan_regs_t *regs, const rfs_bxcan_cfg_t *cfg,
                   void (*poll_hook)(void *ctx), void *poll_ctx);

/// Queue a standard data frame in a free mailbox, aborting a request of the same id still
/// pending (a newer state supersedes it). Returns 0, or -1 (counted) when all three are
/// busy or the controller is bus-off.
int rfs_bxcan_send(rfs_bxcan_t *d, const rfs_can_frame_t *f);

/// For a fault handler (the driver's state not trusted): abort every pending request and
/// put f in the first mailbox that is empty within max_polls reads of TSR (poll_hook, NULL
/// on hardware, between them). Returns 0, or -1 when none emptied (or f is invalid).
int rfs_bxcan_fault_send(rfs_bxcan_regs_t *r, const rfs_can_frame_t *f, uint32_t max_polls,
                         void (*poll_hook)(void *ctx), void *poll_ctx);

/// Take the next received frame: polled, FIFO 0 first, releasing its mailbox; with
/// cfg.rx_irq, the oldest frame of the software queue. false when there is none. Frames
/// the driver cannot represent are dropped and counted.
bool rfs_bxcan_recv(rfs_bxcan_t *d, rfs_can_frame_t *f);

/// The FIFO-pending interrupt of FIFO `fifo` (0 or 1; CAN1_RX0 and CAN1_RX1, which must
/// not preempt each other): move every frame the FIFO holds into the software queue,
/// releasing each mailbox, dropping (and counting) frames when the queue is full. With
/// cfg.rx_irq only; the main loop then never reads the FIFOs itself.
void rfs_bxcan_isr(rfs_bxcan_t *d, unsigned fifo);

/// Check the error state: counts bus-off transitions and aborts pending mailboxes on
/// entering bus-off. Returns true while bus-off.
bool rfs_bxcan_poll(rfs_bxcan_t *d);

#endif /* RFS_BXCAN_H */
