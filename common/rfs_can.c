/* rfs_can.c - the rfseek CAN protocol (layouts in docs/CAN.md and can/rfseek.dbc). */
#include "rfs_can.h"

#include <string.h>

/* Byte helpers: every field is little-endian (Intel). */
static void put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

static void put_u24(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
}

static void put_u32(uint8_t *p, uint32_t v)
{
    put_u16(p, (uint16_t)v);
    put_u16(p + 2, (uint16_t)(v >> 16));
}

static uint16_t get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* Sign-extend a 24-bit two's complement field. */
static int32_t get_s24(const uint8_t *p)
{
    uint32_t v = (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16);
    return (int32_t)(v ^ 0x800000u) - 0x800000;
}

static uint8_t crc8_update(uint8_t crc, uint8_t byte)
{
    crc ^= byte;
    for (int b = 0; b < 8; b++) {
        crc = (uint8_t)((crc & 0x80u) ? ((unsigned)crc << 1) ^ 0x1Du : (unsigned)crc << 1);
    }
    return crc;
}

/* CRC-8 poly 0x1D of each byte value (crc8_update(0, i) without init/xorout): one
 * lookup per byte instead of eight shift steps. Const: lives in flash on the MCU. */
static const uint8_t crc8_table[256] = {
    0x00, 0x1D, 0x3A, 0x27, 0x74, 0x69, 0x4E, 0x53, 0xE8, 0xF5, 0xD2, 0xCF, 0x9C, 0x81, 0xA6, 0xBB,
    0xCD, 0xD0, 0xF7, 0xEA, 0xB9, 0xA4, 0x83, 0x9E, 0x25, 0x38, 0x1F, 0x02, 0x51, 0x4C, 0x6B, 0x76,
    0x87, 0x9A, 0xBD, 0xA0, 0xF3, 0xEE, 0xC9, 0xD4, 0x6F, 0x72, 0x55, 0x48, 0x1B, 0x06, 0x21, 0x3C,
    0x4A, 0x57, 0x70, 0x6D, 0x3E, 0x23, 0x04, 0x19, 0xA2, 0xBF, 0x98, 0x85, 0xD6, 0xCB, 0xEC, 0xF1,
    0x13, 0x0E, 0x29, 0x34, 0x67, 0x7A, 0x5D, 0x40, 0xFB, 0xE6, 0xC1, 0xDC, 0x8F, 0x92, 0xB5, 0xA8,
    0xDE, 0xC3, 0xE4, 0xF9, 0xAA, 0xB7, 0x90, 0x8D, 0x36, 0x2B, 0x0C, 0x11, 0x42, 0x5F, 0x78, 0x65,
    0x94, 0x89, 0xAE, 0xB3, 0xE0, 0xFD, 0xDA, 0xC7, 0x7C, 0x61, 0x46, 0x5B, 0x08, 0x15, 0x32, 0x2F,
    0x59, 0x44, 0x63, 0x7E, 0x2D, 0x30, 0x17, 0x0A, 0xB1, 0xAC, 0x8B, 0x96, 0xC5, 0xD8, 0xFF, 0xE2,
    0x26, 0x3B, 0x1C, 0x01, 0x52, 0x4F, 0x68, 0x75, 0xCE, 0xD3, 0xF4, 0xE9, 0xBA, 0xA7, 0x80, 0x9D,
    0xEB, 0xF6, 0xD1, 0xCC, 0x9F, 0x82, 0xA5, 0xB8, 0x03, 0x1E, 0x39, 0x24, 0x77, 0x6A, 0x4D, 0x50,
    0xA1, 0xBC, 0x9B, 0x86, 0xD5, 0xC8, 0xEF, 0xF2, 0x49, 0x54, 0x73, 0x6E, 0x3D, 0x20, 0x07, 0x1A,
    0x6C, 0x71, 0x56, 0x4B, 0x18, 0x05, 0x22, 0x3F, 0x84, 0x99, 0xBE, 0xA3, 0xF0, 0xED, 0xCA, 0xD7,
    0x35, 0x28, 0x0F, 0x12, 0x41, 0x5C, 0x7B, 0x66, 0xDD, 0xC0, 0xE7, 0xFA, 0xA9, 0xB4, 0x93, 0x8E,
    0xF8, 0xE5, 0xC2, 0xDF, 0x8C, 0x91, 0xB6, 0xAB, 0x10, 0x0D, 0x2A, 0x37, 0x64, 0x79, 0x5E, 0x43,
    0xB2, 0xAF, 0x88, 0x95, 0xC6, 0xDB, 0xFC, 0xE1, 0x5A, 0x47, 0x60, 0x7D, 0x2E, 0x33, 0x14, 0x09,
    0x7F, 0x62, 0x45, 0x58, 0x0B, 0x16, 0x31, 0x2C, 0x97, 0x8A, 0xAD, 0xB0, 0xE3, 0xFE, 0xD9, 0xC4,
};

static uint8_t crc8_update_table(uint8_t crc, uint8_t byte)
{
    return crc8_table[crc ^ byte];
}

uint8_t rfs_can_crc8(const uint8_t *p, uint32_t n)
{
    uint8_t crc = 0xFFu;
    for (uint32_t i = 0; i < n; i++) {
        crc = crc8_update(crc, p[i]);
    }
    return (uint8_t)(crc ^ 0xFFu);
}

uint8_t rfs_can_checksum(uint32_t id, uint8_t dlc, const uint8_t *data)
{
    uint8_t crc = 0xFFu;
    crc = crc8_update_table(crc, (uint8_t)id);
    crc = crc8_update_table(crc, (uint8_t)(id >> 8));
    for (uint8_t i = 0; i + 1u < dlc; i++) {
        crc = crc8_update_table(crc, data[i]);
    }
    return (uint8_t)(crc ^ 0xFFu);
}

uint8_t rfs_can_checksum_bitwise(uint32_t id, uint8_t dlc, const uint8_t *data)
{
    uint8_t crc = 0xFFu;
    crc = crc8_update(crc, (uint8_t)id);
    crc = crc8_update(crc, (uint8_t)(id >> 8));
    for (uint8_t i = 0; i + 1u < dlc; i++) {
        crc = crc8_update(crc, data[i]);
    }
    return (uint8_t)(crc ^ 0xFFu);
}

/* Start a frame: id, DLC, zeroed payload, counter and flags nibble in data[0]. */
static void frame_begin(rfs_can_frame_t *f, uint32_t id, uint8_t dlc, uint8_t counter, uint8_t high_nibble)
{
    memset(f, 0, sizeof(*f));
    f->id = id;
    f->dlc = dlc;
    f->data[0] = (uint8_t)((counter & 0x0Fu) | ((high_nibble & 0x0Fu) << 4));
}

static void frame_seal(rfs_can_frame_t *f)
{
    f->data[f->dlc - 1u] = rfs_can_checksum(f->id, f->dlc, f->data);
}

/* Common checks of a received frame against one layout. */
static rfs_can_err_t frame_check(const rfs_can_frame_t *f, uint32_t id, uint8_t dlc)
{
    if (f->id != id) {
        return RFS_CAN_E_ID;
    }
    if (f->dlc != dlc) {
        return RFS_CAN_E_DLC;
    }
    if (f->data[dlc - 1u] != rfs_can_checksum(f->id, f->dlc, f->data)) {
        return RFS_CAN_E_CHECKSUM;
    }
    return RFS_CAN_OK;
}

static int32_t sat_s24(int32_t v)
{
    return v > RFS_CAN_POS_MM_MAX ? RFS_CAN_POS_MM_MAX : (v < RFS_CAN_POS_MM_MIN ? RFS_CAN_POS_MM_MIN : v);
}

void rfs_can_pack_wheel(const rfs_can_wheel_t *w, uint8_t counter, rfs_can_frame_t *f)
{
    frame_begin(f, RFS_CAN_ID_WHEEL_CMD, RFS_CAN_DLC_WHEEL_CMD, counter, w->flags);
    put_u16(&f->data[1], (uint16_t)w->left_mm_s);
    put_u16(&f->data[3], (uint16_t)w->right_mm_s);
    frame_seal(f);
}

void rfs_can_pack_pose_xy(const rfs_can_pose_t *p, uint8_t counter, rfs_can_frame_t *f)
{
    frame_begin(f, RFS_CAN_ID_POSE_XY, RFS_CAN_DLC_POSE_XY, counter, 0);
    put_u24(&f->data[1], (uint32_t)sat_s24(p->x_mm));
    put_u24(&f->data[4], (uint32_t)sat_s24(p->y_mm));
    frame_seal(f);
}

void rfs_can_pack_pose_th(const rfs_can_pose_t *p, uint8_t counter, rfs_can_frame_t *f)
{
    frame_begin(f, RFS_CAN_ID_POSE_TH, RFS_CAN_DLC_POSE_TH, counter, 0);
    put_u16(&f->data[1], (uint16_t)p->theta_q13);
    put_u32(&f->data[3], p->t_us32);
    frame_seal(f);
}

void rfs_can_pack_rssi(const rfs_can_rssi_t *r, uint8_t counter, rfs_can_frame_t *f)
{
    frame_begin(f, RFS_CAN_ID_RSSI, RFS_CAN_DLC_RSSI, counter, r->src);
    f->data[1] = (uint8_t)r->dbm;
    f->data[2] = r->seq;
    put_u32(&f->data[3], r->t_us32);
    frame_seal(f);
}

void rfs_can_pack_receiver(const rfs_can_receiver_t *r, uint8_t counter, rfs_can_frame_t *f)
{
    frame_begin(f, RFS_CAN_ID_RX_STATUS, RFS_CAN_DLC_RX_STATUS, counter, 0);
    put_u32(&f->data[1], r->t_us32);
    frame_seal(f);
}

void rfs_can_pack_status(const rfs_can_status_t *s, uint8_t counter, rfs_can_frame_t *f)
{
    frame_begin(f, RFS_CAN_ID_STATUS, RFS_CAN_DLC_STATUS, counter, (uint8_t)(s->state & 0x3u));
    f->data[1] = (uint8_t)((s->kind & 0x3u) | ((s->relearned ? 1u : 0u) << 2) |
                           ((s->line_search ? 1u : 0u) << 3) | ((s->prev & 0x7u) << 4) |
                           ((s->configured ? 1u : 0u) << 7));
    f->data[2] = s->faults;
    put_u32(&f->data[3], s->iteration);
    frame_seal(f);
}

void rfs_can_pack_config(const rfs_can_config_t *c, uint8_t counter, rfs_can_frame_t *f)
{
    frame_begin(f, RFS_CAN_ID_CONFIG, RFS_CAN_DLC_CONFIG, counter,
                (uint8_t)((c->target & 0x3u) | ((c->fit_early & 0x3u) << 2)));
    f->data[1] = (uint8_t)((c->strategy & 0xFu) | ((c->model & 0xFu) << 4));
    put_u16(&f->data[2], (uint16_t)c->p0_min);
    put_u24(&f->data[4], c->seed & 0xFFFFFFu);
    frame_seal(f);
}

rfs_can_err_t rfs_can_unpack_wheel(const rfs_can_frame_t *f, rfs_can_wheel_t *w, uint8_t *counter)
{
    rfs_can_err_t e = frame_check(f, RFS_CAN_ID_WHEEL_CMD, RFS_CAN_DLC_WHEEL_CMD);
    if (e != RFS_CAN_OK) {
        return e;
    }
    if ((f->data[0] >> 4) & ~RFS_CAN_WHEEL_STOP) {
        return RFS_CAN_E_RANGE;
    }
    w->flags = (uint8_t)(f->data[0] >> 4);
    w->left_mm_s = (int16_t)get_u16(&f->data[1]);
    w->right_mm_s = (int16_t)get_u16(&f->data[3]);
    *counter = f->data[0] & 0x0Fu;
    return RFS_CAN_OK;
}

rfs_can_err_t rfs_can_unpack_pose_xy(const rfs_can_frame_t *f, rfs_can_pose_t *p, uint8_t *counter)
{
    rfs_can_err_t e = frame_check(f, RFS_CAN_ID_POSE_XY, RFS_CAN_DLC_POSE_XY);
    if (e != RFS_CAN_OK) {
        return e;
    }
    if (f->data[0] >> 4) {
        return RFS_CAN_E_RANGE;
    }
    p->x_mm = get_s24(&f->data[1]);
    p->y_mm = get_s24(&f->data[4]);
    *counter = f->data[0] & 0x0Fu;
    return RFS_CAN_OK;
}

rfs_can_err_t rfs_can_unpack_pose_th(const rfs_can_frame_t *f, rfs_can_pose_t *p, uint8_t *counter)
{
    rfs_can_err_t e = frame_check(f, RFS_CAN_ID_POSE_TH, RFS_CAN_DLC_POSE_TH);
    if (e != RFS_CAN_OK) {
        return e;
    }
    int16_t theta = (int16_t)get_u16(&f->data[1]);
    /* (-pi, pi] in Q2.13 is (-25736, 25736]; anything outside is a corrupt sender. */
    if ((f->data[0] >> 4) || theta > 25736 || theta < -25736) {
        return RFS_CAN_E_RANGE;
    }
    p->theta_q13 = theta;
    p->t_us32 = get_u32(&f->data[3]);
    *counter = f->data[0] & 0x0Fu;
    return RFS_CAN_OK;
}

rfs_can_err_t rfs_can_unpack_rssi(const rfs_can_frame_t *f, rfs_can_rssi_t *r, uint8_t *counter)
{
    rfs_can_err_t e = frame_check(f, RFS_CAN_ID_RSSI, RFS_CAN_DLC_RSSI);
    if (e != RFS_CAN_OK) {
        return e;
    }
    r->src = (uint8_t)(f->data[0] >> 4);
    r->dbm = (int8_t)f->data[1];
    r->seq = f->data[2];
    r->t_us32 = get_u32(&f->data[3]);
    *counter = f->data[0] & 0x0Fu;
    return RFS_CAN_OK;
}

rfs_can_err_t rfs_can_unpack_receiver(const rfs_can_frame_t *f, rfs_can_receiver_t *r, uint8_t *counter)
{
    rfs_can_err_t e = frame_check(f, RFS_CAN_ID_RX_STATUS, RFS_CAN_DLC_RX_STATUS);
    if (e != RFS_CAN_OK) {
        return e;
    }
    if (f->data[0] >> 4) {
        return RFS_CAN_E_RANGE;
    }
    r->t_us32 = get_u32(&f->data[1]);
    *counter = f->data[0] & 0x0Fu;
    return RFS_CAN_OK;
}

rfs_can_err_t rfs_can_unpack_config(const rfs_can_frame_t *f, rfs_can_config_t *c, uint8_t *counter)
{
    rfs_can_err_t e = frame_check(f, RFS_CAN_ID_CONFIG, RFS_CAN_DLC_CONFIG);
    if (e != RFS_CAN_OK) {
        return e;
    }
    const uint8_t target = (uint8_t)((f->data[0] >> 4) & 0x3u);
    const uint8_t fit_early = (uint8_t)(f->data[0] >> 6);
    const uint8_t strategy = (uint8_t)(f->data[1] & 0xFu);
    const uint8_t model = (uint8_t)(f->data[1] >> 4);
    const int16_t p0 = (int16_t)get_u16(&f->data[2]);
    if (target > 1u || fit_early > (uint8_t)RFS_CAN_FIT_EARLY_ON || strategy >= (uint8_t)RFS_SEEK_STRATEGY_COUNT ||
        model >= (uint8_t)RFS_CAN_NMODELS ||
        (p0 != RFS_CAN_P0_NONE && (p0 < RFS_CAN_P0_MIN || p0 > RFS_CAN_P0_MAX))) {
        return RFS_CAN_E_RANGE;
    }
    c->target = target;
    c->strategy = strategy;
    c->model = model;
    c->p0_min = p0;
    c->seed = (uint32_t)f->data[4] | ((uint32_t)f->data[5] << 8) | ((uint32_t)f->data[6] << 16);
    c->fit_early = fit_early;
    *counter = f->data[0] & 0x0Fu;
    return RFS_CAN_OK;
}

rfs_can_err_t rfs_can_unpack_status(const rfs_can_frame_t *f, rfs_can_status_t *s, uint8_t *counter)
{
    rfs_can_err_t e = frame_check(f, RFS_CAN_ID_STATUS, RFS_CAN_DLC_STATUS);
    if (e != RFS_CAN_OK) {
        return e;
    }
    uint8_t prev = (uint8_t)((f->data[1] >> 4) & 0x7u);
    if ((f->data[0] >> 6) || prev > RFS_DRIVE_BLOCKED) {
        return RFS_CAN_E_RANGE;
    }
    s->state = (uint8_t)((f->data[0] >> 4) & 0x3u);
    s->kind = (uint8_t)(f->data[1] & 0x3u);
    s->relearned = (f->data[1] & 0x4u) != 0;
    s->line_search = (f->data[1] & 0x8u) != 0;
    s->prev = prev;
    s->faults = f->data[2];
    s->iteration = get_u32(&f->data[3]);
    s->configured = (f->data[1] & 0x80u) != 0;
    *counter = f->data[0] & 0x0Fu;
    return RFS_CAN_OK;
}

int64_t rfs_can_unwrap_time(int64_t ref_us, uint32_t raw)
{
    /* Difference modulo 2^32 reinterpreted as signed: in [-2^31, 2^31). */
    int32_t d = (int32_t)(raw - (uint32_t)(uint64_t)ref_us);
    if (d > 0 && ref_us > INT64_MAX - d) {
        return INT64_MAX;
    }
    if (d < 0 && ref_us < INT64_MIN - d) {
        return INT64_MIN;
    }
    return ref_us + d;
}

rfs_q16_t rfs_can_mm_to_q16(int32_t mm)
{
    return rfs_sat32(rfs_sdiv64_round((int64_t)mm * 65536, 1000));
}

int32_t rfs_can_q16_to_mm(rfs_q16_t q)
{
    return sat_s24((int32_t)rfs_sdiv64_round((int64_t)q * 1000, 65536));
}

int16_t rfs_can_q16_to_theta(rfs_q16_t q)
{
    return rfs_sat16(((int64_t)q + 4) >> 3);
}

rfs_pose_t rfs_can_pose_to_core(const rfs_can_pose_t *p, int64_t t_us)
{
    rfs_pose_t pose;
    pose.t_us = t_us;
    pose.x = rfs_can_mm_to_q16(p->x_mm);
    pose.y = rfs_can_mm_to_q16(p->y_mm);
    pose.theta = rfs_can_theta_to_q16(p->theta_q13);
    return pose;
}

rfs_can_pose_t rfs_can_pose_from_core(const rfs_pose_t *pose)
{
    rfs_can_pose_t p;
    p.x_mm = rfs_can_q16_to_mm(pose->x);
    p.y_mm = rfs_can_q16_to_mm(pose->y);
    p.theta_q13 = rfs_can_q16_to_theta(pose->theta);
    p.t_us32 = rfs_can_wrap_time(pose->t_us);
    return p;
}

uint8_t rfs_can_status_kind(rfs_seek_kind_t k)
{
    /* The field's 2 bits hold the meta strategies' kinds; a baseline's directed steps
     * (gradient, run) go out as greedy, its exploring ones (probe, tumble) as epsilon. */
    return (uint8_t)(k == RFS_SEEK_GRADIENT || k == RFS_SEEK_RUN ? RFS_SEEK_GREEDY
                     : k == RFS_SEEK_PROBE || k == RFS_SEEK_TUMBLE ? RFS_SEEK_EPSILON
                     : (uint32_t)k <= (uint32_t)RFS_SEEK_EPSILON ? k
                                                                 : RFS_SEEK_NONE);
}

void rfs_can_from_seek_out(const rfs_seek_out_t *out, rfs_can_status_t *status, rfs_can_wheel_t *wheel)
{
    status->state = (uint8_t)out->state;
    status->kind = rfs_can_status_kind(out->decision.kind);
    status->prev = (uint8_t)out->decision.prev;
    status->relearned = out->decision.relearned;
    status->line_search = out->decision.line_search;
    status->faults = (uint8_t)out->faults;
    status->iteration = out->decision.iteration;
    status->configured = false; /* the seeker knows of no CONFIG frame: the application's */
    wheel->left_mm_s = out->left_mm_s;
    wheel->right_mm_s = out->right_mm_s;
    wheel->flags = out->state == RFS_SEEK_DRIVING ? 0u : RFS_CAN_WHEEL_STOP;
}

void rfs_can_tx_init(rfs_can_tx_t *tx)
{
    memset(tx, 0, sizeof(*tx));
}

static uint8_t tx_next(rfs_can_tx_t *tx, rfs_can_msg_idx_t i)
{
    uint8_t c = tx->counter[i];
    tx->counter[i] = (uint8_t)((c + 1u) & 0x0Fu);
    return c;
}

void rfs_can_tx_wheel(rfs_can_tx_t *tx, const rfs_can_wheel_t *w, rfs_can_frame_t *f)
{
    rfs_can_pack_wheel(w, tx_next(tx, RFS_CAN_IDX_WHEEL_CMD), f);
}

void rfs_can_tx_pose(rfs_can_tx_t *tx, const rfs_can_pose_t *p, rfs_can_frame_t *xy, rfs_can_frame_t *th)
{
    /* Both halves carry one counter so the receiver can pair them. */
    uint8_t c = tx_next(tx, RFS_CAN_IDX_POSE_XY);
    tx->counter[RFS_CAN_IDX_POSE_TH] = tx->counter[RFS_CAN_IDX_POSE_XY];
    rfs_can_pack_pose_xy(p, c, xy);
    rfs_can_pack_pose_th(p, c, th);
}

void rfs_can_tx_rssi(rfs_can_tx_t *tx, const rfs_can_rssi_t *r, rfs_can_frame_t *f)
{
    rfs_can_pack_rssi(r, tx_next(tx, RFS_CAN_IDX_RSSI), f);
}

void rfs_can_tx_receiver(rfs_can_tx_t *tx, const rfs_can_receiver_t *r, rfs_can_frame_t *f)
{
    rfs_can_pack_receiver(r, tx_next(tx, RFS_CAN_IDX_RX_STATUS), f);
}

void rfs_can_tx_config(rfs_can_tx_t *tx, const rfs_can_config_t *c, rfs_can_frame_t *f)
{
    rfs_can_pack_config(c, tx_next(tx, RFS_CAN_IDX_CONFIG), f);
}

void rfs_can_tx_status(rfs_can_tx_t *tx, const rfs_can_status_t *s, rfs_can_frame_t *f)
{
    rfs_can_pack_status(s, tx_next(tx, RFS_CAN_IDX_STATUS), f);
}

rfs_can_rx_cfg_t rfs_can_rx_cfg_default(void)
{
    rfs_can_rx_cfg_t c;
    c.max_age_us = 1000000;
    c.max_future_us = 100000;
    c.follow_epoch = false;
    c.resync_us = 2000000;
    return c;
}

int rfs_can_rx_init(rfs_can_rx_t *rx, const rfs_can_rx_cfg_t *cfg)
{
    const int64_t hour_us = 3600LL * 1000000LL;
    if (cfg->max_age_us <= 0 || cfg->max_age_us > hour_us || cfg->max_future_us < 0 ||
        cfg->max_future_us > hour_us || cfg->resync_us <= 0 || cfg->resync_us > hour_us) {
        return -1;
    }
    memset(rx, 0, sizeof(*rx));
    rx->cfg = *cfg;
    return 0;
}

static rfs_can_err_t drop(rfs_can_rx_t *rx, rfs_can_err_t e)
{
    if (rx->dropped[e] < UINT32_MAX) {
        rx->dropped[e]++;
    }
    return e;
}

static void bump(uint32_t *v, uint32_t by)
{
    *v = (*v > UINT32_MAX - by) ? UINT32_MAX : *v + by;
}

/* Counter check: a repeat is a duplicate (reject); a jump is counted and accepted. */
static rfs_can_err_t counter_check(const rfs_can_rx_t *rx, rfs_can_msg_idx_t i, uint8_t c)
{
    if (rx->have_counter[i] && c == rx->last_counter[i]) {
        return RFS_CAN_E_REPEAT;
    }
    return RFS_CAN_OK;
}

static void counter_accept(rfs_can_rx_t *rx, rfs_can_msg_idx_t i, uint8_t c)
{
    if (rx->have_counter[i]) {
        uint8_t gap = (uint8_t)((c - rx->last_counter[i] - 1u) & 0x0Fu);
        if (gap != 0) {
            bump(&rx->msg[i].counter_jumps, 1);
            bump(&rx->msg[i].lost, gap);
        }
    }
    rx->last_counter[i] = c;
    rx->have_counter[i] = true;
    bump(&rx->msg[i].accepted, 1);
}

/* Time window check of an unwrapped timestamp against now and the stream's newest. */
static rfs_can_err_t time_check(const rfs_can_rx_t *rx, int64_t t, int64_t now_us, bool have_last, int64_t last)
{
    if (t < now_us - rx->cfg.max_age_us) {
        return RFS_CAN_E_STALE;
    }
    if (t > now_us + rx->cfg.max_future_us) {
        return RFS_CAN_E_FUTURE;
    }
    if (have_last && t < last) {
        return RFS_CAN_E_ORDER;
    }
    return RFS_CAN_OK;
}

/* The senders' epoch (follow_epoch; docs/CAN.md, "Time on the bus"). The offset follows
 * the smallest latency seen: a frame from the future moves it at once, an older one pulls
 * it back by at most 1/2048 of the local time elapsed (about 490 ppm, five times the
 * crystals' 100 ppm), so a stream lagging 1 s (docs/FAULTS.md, pose_past) stays stale
 * while others are on time. Only frames that passed every check but the time window get
 * here. Scaling and overflow: times are within 2^60 (rfs_can_rx_frame); the allowance's
 * elapsed time is capped at 2^21 us, a pull at 1,024 us. */
#define EPOCH_PULL_SHIFT 11
#define EPOCH_PULL_CAP_US ((int64_t)1 << 21)

/* A stamp in local time: seeding the offset on the first frame, and re-seeding it when
 * every time-bearing frame has missed the window for resync_us (the senders restarted). */
static int64_t epoch_read(rfs_can_rx_t *rx, uint32_t raw, int64_t now_us)
{
    if (!rx->cfg.follow_epoch) {
        return rfs_can_unwrap_time(now_us, raw);
    }
    int64_t t = rfs_can_unwrap_time(now_us, raw - rx->epoch_off);
    const bool fresh = t >= now_us - rx->cfg.max_future_us && t <= now_us + rx->cfg.max_future_us;
    const bool resync = rx->have_late && !fresh && now_us - rx->late_us >= rx->cfg.resync_us;
    if (!rx->have_epoch || resync) {
        if (rx->have_epoch) {
            bump(&rx->resyncs, 1);
        }
        rx->epoch_off = raw - rfs_can_wrap_time(now_us);
        rx->have_epoch = true;
        rx->have_late = false;
        rx->pull_us = now_us;
        t = now_us;
    }
    return t;
}

/* After the window check of a stamp read by epoch_read: a dropped or late frame marks the
 * start of missed frames; an accepted one moves the offset. Returns the accepted stamp as
 * the moved offset reads it (never later than now: order within a stream is kept). */
static int64_t epoch_note(rfs_can_rx_t *rx, rfs_can_err_t e, int64_t t, int64_t now_us)
{
    if (!rx->cfg.follow_epoch) {
        return t;
    }
    const int64_t age = now_us - t;
    if (e != RFS_CAN_OK || age > rx->cfg.max_future_us) {
        if (!rx->have_late) {
            rx->have_late = true;
            rx->late_us = now_us;
        }
    } else {
        rx->have_late = false;
    }
    if (e != RFS_CAN_OK) {
        return t;
    }
    if (age < 0) {
        rx->epoch_off += (uint32_t)(uint64_t)(-age);
        rx->pull_us = now_us;
        return now_us;
    }
    int64_t el = now_us - rx->pull_us;
    el = el < 0 ? 0 : (el > EPOCH_PULL_CAP_US ? EPOCH_PULL_CAP_US : el);
    int64_t step = el >> EPOCH_PULL_SHIFT;
    step = step > age ? age : step;
    rx->epoch_off -= (uint32_t)step;
    rx->pull_us = now_us - el + (step << EPOCH_PULL_SHIFT);
    return t + step;
}

/* A stamp in local time and its window check (time_check): the one path of every
 * time-bearing frame. */
static rfs_can_err_t rx_time(rfs_can_rx_t *rx, uint32_t raw, int64_t now_us, bool have_last,
                             int64_t last, int64_t *t)
{
    *t = epoch_read(rx, raw, now_us);
    const rfs_can_err_t e = time_check(rx, *t, now_us, have_last, last);
    *t = epoch_note(rx, e, *t, now_us);
    return e;
}

/* WHEEL_CMD: a counter check. */
static rfs_can_err_t rx_wheel(rfs_can_rx_t *rx, const rfs_can_frame_t *f, rfs_can_msg_t *msg)
{
    uint8_t c = 0;
    rfs_can_wheel_t w;
    rfs_can_err_t e = rfs_can_unpack_wheel(f, &w, &c);
    if (e == RFS_CAN_OK) {
        e = counter_check(rx, RFS_CAN_IDX_WHEEL_CMD, c);
    }
    if (e != RFS_CAN_OK) {
        return drop(rx, e);
    }
    counter_accept(rx, RFS_CAN_IDX_WHEEL_CMD, c);
    msg->kind = RFS_CAN_MSG_WHEEL;
    msg->wheel = w;
    return RFS_CAN_OK;
}

/* STATUS: a counter check. */
static rfs_can_err_t rx_status(rfs_can_rx_t *rx, const rfs_can_frame_t *f, rfs_can_msg_t *msg)
{
    uint8_t c = 0;
    rfs_can_status_t s;
    rfs_can_err_t e = rfs_can_unpack_status(f, &s, &c);
    if (e == RFS_CAN_OK) {
        e = counter_check(rx, RFS_CAN_IDX_STATUS, c);
    }
    if (e != RFS_CAN_OK) {
        return drop(rx, e);
    }
    counter_accept(rx, RFS_CAN_IDX_STATUS, c);
    msg->kind = RFS_CAN_MSG_STATUS;
    msg->status = s;
    return RFS_CAN_OK;
}

/* POSE_XY: the first half of a pose, held until its POSE_TH. */
static rfs_can_err_t rx_pose_xy(rfs_can_rx_t *rx, const rfs_can_frame_t *f)
{
    uint8_t c = 0;
    rfs_can_pose_t p;
    rfs_can_err_t e = rfs_can_unpack_pose_xy(f, &p, &c);
    if (e == RFS_CAN_OK) {
        e = counter_check(rx, RFS_CAN_IDX_POSE_XY, c);
    }
    if (e != RFS_CAN_OK) {
        return drop(rx, e);
    }
    if (rx->have_pending) {
        /* The previous XY never got its TH: that pose is lost. */
        (void)drop(rx, RFS_CAN_E_PAIR);
    }
    counter_accept(rx, RFS_CAN_IDX_POSE_XY, c);
    rx->pending.x_mm = p.x_mm;
    rx->pending.y_mm = p.y_mm;
    rx->pending_counter = c;
    rx->have_pending = true;
    return RFS_CAN_OK;
}

/* POSE_TH: completes the pose begun by the POSE_XY of the same counter. */
static rfs_can_err_t rx_pose_th(rfs_can_rx_t *rx, const rfs_can_frame_t *f, int64_t now_us,
                                rfs_can_msg_t *msg)
{
    uint8_t c = 0;
    rfs_can_pose_t p;
    rfs_can_err_t e = rfs_can_unpack_pose_th(f, &p, &c);
    if (e == RFS_CAN_OK) {
        e = counter_check(rx, RFS_CAN_IDX_POSE_TH, c);
    }
    if (e == RFS_CAN_OK && (!rx->have_pending || rx->pending_counter != c)) {
        e = RFS_CAN_E_PAIR;
    }
    int64_t t = 0;
    if (e == RFS_CAN_OK) {
        e = rx_time(rx, p.t_us32, now_us, rx->have_pose, rx->last_pose_us, &t);
    }
    if (e != RFS_CAN_OK) {
        if (e != RFS_CAN_E_PAIR && e != RFS_CAN_E_REPEAT) {
            rx->have_pending = false;
        }
        return drop(rx, e);
    }
    counter_accept(rx, RFS_CAN_IDX_POSE_TH, c);
    rx->have_pending = false;
    p.x_mm = rx->pending.x_mm;
    p.y_mm = rx->pending.y_mm;
    rx->last_pose_us = t;
    rx->have_pose = true;
    msg->kind = RFS_CAN_MSG_POSE;
    msg->pose = rfs_can_pose_to_core(&p, t);
    return RFS_CAN_OK;
}

/* RSSI: a measurement, in its source's own stream (time window, sequence gaps). */
static rfs_can_err_t rx_rssi(rfs_can_rx_t *rx, const rfs_can_frame_t *f, int64_t now_us,
                             rfs_can_msg_t *msg)
{
    uint8_t c = 0;
    rfs_can_rssi_t r;
    rfs_can_err_t e = rfs_can_unpack_rssi(f, &r, &c);
    if (e == RFS_CAN_OK) {
        e = counter_check(rx, RFS_CAN_IDX_RSSI, c);
    }
    int64_t t = 0;
    if (e == RFS_CAN_OK) {
        e = rx_time(rx, r.t_us32, now_us, (rx->have_rssi >> r.src) & 1u, rx->last_rssi_us[r.src], &t);
    }
    if (e != RFS_CAN_OK) {
        return drop(rx, e);
    }
    counter_accept(rx, RFS_CAN_IDX_RSSI, c);
    if (((rx->have_rssi >> r.src) & 1u) && r.seq != rx->last_seq[r.src]) {
        bump(&rx->rssi_seq_gaps, (uint8_t)(r.seq - rx->last_seq[r.src] - 1u));
    }
    rx->have_rssi = (uint16_t)(rx->have_rssi | (1u << r.src));
    rx->last_rssi_us[r.src] = t;
    rx->last_seq[r.src] = r.seq;
    msg->kind = RFS_CAN_MSG_RSSI;
    msg->rssi_src = r.src;
    msg->rssi_dbm = r.dbm;
    msg->rssi_seq = r.seq;
    msg->rssi_t_us = t;
    return RFS_CAN_OK;
}

/* RX_STATUS: the same time window as the packets (docs/CAN.md, "0x121 RX_STATUS"): the
 * heartbeat comes from the same capture clock, so a stale, future or reordered one is
 * dropped alike, in its own stream (a heartbeat may follow a packet stamped later). */
static rfs_can_err_t rx_receiver(rfs_can_rx_t *rx, const rfs_can_frame_t *f, int64_t now_us,
                                 rfs_can_msg_t *msg)
{
    uint8_t c = 0;
    rfs_can_receiver_t r;
    rfs_can_err_t e = rfs_can_unpack_receiver(f, &r, &c);
    if (e == RFS_CAN_OK) {
        e = counter_check(rx, RFS_CAN_IDX_RX_STATUS, c);
    }
    int64_t t = 0;
    if (e == RFS_CAN_OK) {
        e = rx_time(rx, r.t_us32, now_us, rx->have_receiver, rx->last_receiver_us, &t);
    }
    if (e != RFS_CAN_OK) {
        return drop(rx, e);
    }
    counter_accept(rx, RFS_CAN_IDX_RX_STATUS, c);
    rx->last_receiver_us = t;
    rx->have_receiver = true;
    msg->kind = RFS_CAN_MSG_RECEIVER;
    msg->receiver_t_us = t;
    return RFS_CAN_OK;
}

/* CONFIG: a counter check (no time: it is not a measurement). */
static rfs_can_err_t rx_config(rfs_can_rx_t *rx, const rfs_can_frame_t *f, rfs_can_msg_t *msg)
{
    uint8_t c = 0;
    rfs_can_config_t cf;
    rfs_can_err_t e = rfs_can_unpack_config(f, &cf, &c);
    if (e == RFS_CAN_OK) {
        e = counter_check(rx, RFS_CAN_IDX_CONFIG, c);
    }
    if (e != RFS_CAN_OK) {
        return drop(rx, e);
    }
    counter_accept(rx, RFS_CAN_IDX_CONFIG, c);
    msg->kind = RFS_CAN_MSG_CONFIG;
    msg->config = cf;
    return RFS_CAN_OK;
}

rfs_can_err_t rfs_can_rx_frame(rfs_can_rx_t *rx, const rfs_can_frame_t *f, int64_t now_us, rfs_can_msg_t *msg)
{
    msg->kind = RFS_CAN_MSG_NONE;
    /* Keep the window arithmetic far from the int64 limits. */
    const int64_t lim = (int64_t)1 << 60;
    now_us = now_us > lim ? lim : (now_us < -lim ? -lim : now_us);
    switch (f->id) {
    case RFS_CAN_ID_WHEEL_CMD: return rx_wheel(rx, f, msg);
    case RFS_CAN_ID_STATUS: return rx_status(rx, f, msg);
    case RFS_CAN_ID_POSE_XY: return rx_pose_xy(rx, f);
    case RFS_CAN_ID_POSE_TH: return rx_pose_th(rx, f, now_us, msg);
    case RFS_CAN_ID_RSSI: return rx_rssi(rx, f, now_us, msg);
    case RFS_CAN_ID_RX_STATUS: return rx_receiver(rx, f, now_us, msg);
    case RFS_CAN_ID_CONFIG: return rx_config(rx, f, msg);
    default: return drop(rx, RFS_CAN_E_ID);
    }
}

uint32_t rfs_can_rx_dropped_total(const rfs_can_rx_t *rx)
{
    uint32_t n = 0;
    for (unsigned i = 1; i < RFS_CAN_NERR; i++) {
        bump(&n, rx->dropped[i]);
    }
    return n;
}

const char *rfs_can_model_name(uint8_t code)
{
    static const char *const names[RFS_CAN_NMODELS] = {"ridge", "mlp", "knn", "radius", "pathloss"};
    return code < (uint8_t)RFS_CAN_NMODELS ? names[code] : NULL;
}

rfs_q16_t rfs_can_p0_to_q16(int16_t raw)
{
    return raw == RFS_CAN_P0_NONE ? INT32_MIN : (rfs_q16_t)raw * 512;
}

const char *rfs_can_err_str(rfs_can_err_t e)
{
    static const char *const names[RFS_CAN_NERR] = {
        "ok", "id", "dlc", "checksum", "range", "repeat", "pair", "stale", "future", "order",
    };
    return (unsigned)e < RFS_CAN_NERR ? names[e] : "?";
}
