/* rfs_replay.c - the recorded stream format (see rfs_replay.h). Portable: only memcpy and
 * memset, explicit little-endian byte handling, every length checked before a read. */
#include "rfs_replay.h"

#include <stddef.h>
#include <string.h>

static const uint8_t k_magic[4] = {'R', 'F', 'S', 'R'};

static uint16_t rd16(const uint8_t *p) { return (uint16_t)(p[0] | ((uint16_t)p[1] << 8)); }
static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}
static uint64_t rd64(const uint8_t *p) { return rd32(p) | ((uint64_t)rd32(p + 4) << 32); }
static int64_t rds64(const uint8_t *p) { return (int64_t)rd64(p); }
static int32_t rds32(const uint8_t *p) { return (int32_t)rd32(p); }

static uint8_t *wr16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    return p + 2;
}
static uint8_t *wr32(uint8_t *p, uint32_t v)
{
    p = wr16(p, (uint16_t)v);
    return wr16(p, (uint16_t)(v >> 16));
}
static uint8_t *wr64(uint8_t *p, uint64_t v)
{
    p = wr32(p, (uint32_t)v);
    return wr32(p, (uint32_t)(v >> 32));
}

void rfs_replay_header(uint8_t buf[RFS_REPLAY_HEADER_LEN])
{
    memcpy(buf, k_magic, 4);
    wr16(buf + 4, RFS_REPLAY_VERSION);
    wr16(buf + 6, 0);
}

int rfs_replay_check_header(const uint8_t *buf, uint32_t len)
{
    if (len < RFS_REPLAY_HEADER_LEN || memcmp(buf, k_magic, 4) != 0) {
        return -1;
    }
    return (rd16(buf + 4) == RFS_REPLAY_VERSION && rd16(buf + 6) == 0) ? 0 : -1;
}

/* Fixed payload length of each type; -1 = variable (chunks), -2 = unknown type. */
static int payload_len(uint8_t type)
{
    switch (type) {
    case RFS_REPLAY_CFG: return -3; /* 14, a model name of 0..15 bytes, a choice of 0 or 4 */
    case RFS_REPLAY_MAP: return 17;
    case RFS_REPLAY_MAP_FREE:
    case RFS_REPLAY_MAP_WALL: return -1;
    case RFS_REPLAY_POSE: return 28;
    case RFS_REPLAY_RSSI: return 18;
    case RFS_REPLAY_CAN: return 21;
    case RFS_REPLAY_RECEIVER: return 16;
    case RFS_REPLAY_STEP: return 8;
    case RFS_REPLAY_BUS: return 9;
    case RFS_REPLAY_RESET: return 8;
    case RFS_REPLAY_END: return 0;
    case RFS_REPLAY_OUT: return 16;
    case RFS_REPLAY_DECISION: return 57;
    case RFS_REPLAY_CAN_TX: return 21;
    default: return -2;
    }
}

static rfs_replay_status_t bad(rfs_replay_rec_t *rec, const char *why)
{
    rec->error = why;
    return RFS_REPLAY_BAD;
}

/* The decision body, 57 bytes (shared by parse and encode through these two). */
static void get_decision(const uint8_t *p, rfs_seek_decision_t *d)
{
    d->iteration = rd32(p);
    d->t_us = rds64(p + 4);
    d->kind = (rfs_seek_kind_t)p[12];
    d->relearned = (p[13] & 1u) != 0;
    d->line_search = (p[13] & 2u) != 0;
    d->model_valid = (p[13] & 4u) != 0;
    d->mean_valid = (p[13] & 8u) != 0;
    d->prev = (rfs_drive_status_t)p[14];
    const uint8_t *q = p + 15;
    rfs_q16_t *fields[10] = {&d->prediction, &d->mean, &d->epsilon, &d->x, &d->y,
                             &d->goal_x, &d->goal_y, &d->max_x, &d->max_y, &d->path_len};
    for (unsigned i = 0; i < 10u; i++) {
        *fields[i] = rds32(q + 4u * i);
    }
    d->samples = rd16(p + 55);
}

static uint8_t *put_decision(uint8_t *p, const rfs_seek_decision_t *d)
{
    p = wr32(p, d->iteration);
    p = wr64(p, (uint64_t)d->t_us);
    *p++ = (uint8_t)d->kind;
    *p++ = (uint8_t)((d->relearned ? 1u : 0u) | (d->line_search ? 2u : 0u) |
                     (d->model_valid ? 4u : 0u) | (d->mean_valid ? 8u : 0u));
    *p++ = (uint8_t)d->prev;
    const rfs_q16_t fields[10] = {d->prediction, d->mean, d->epsilon, d->x, d->y,
                                  d->goal_x, d->goal_y, d->max_x, d->max_y, d->path_len};
    for (unsigned i = 0; i < 10u; i++) {
        p = wr32(p, (uint32_t)fields[i]);
    }
    return wr16(p, d->samples);
}

/* The record header's length n checked against the type's: NULL, or why it is wrong. */
static const char *check_length(uint8_t type, uint8_t n)
{
    const int want = payload_len(type);
    if (want == -2) {
        return "unknown record type";
    }
    if (want >= 0 && n != (uint8_t)want) {
        return "wrong record length for its type";
    }
    if (want == -3 && (n < 14u || n > 14u + RFS_REPLAY_MODEL_NAME_MAX + RFS_REPLAY_CHOICE_LEN)) {
        return "CFG length out of range";
    }
    if (want == -1 && (n < 5u || n > 4u + RFS_REPLAY_CHUNK)) {
        return "map chunk length out of range";
    }
    return NULL;
}

/* A CFG payload p of n bytes into rec: NULL, or why it is malformed. */
static const char *get_cfg(const uint8_t *p, uint8_t n, rfs_replay_rec_t *rec)
{
    rec->u.cfg.seed = rd64(p);
    /* The target byte: the target in bits 0-1, flags above (bits 2-6 unused so far). */
    rec->u.cfg.target = (uint8_t)(p[8] & 0x03u);
    rec->u.cfg.fit_early = (p[8] & RFS_REPLAY_CFG_FIT_EARLY) != 0u;
    rec->u.cfg.node = p[9];
    rec->u.cfg.fit_budget = rd32(p + 10);
    if ((p[8] & (uint8_t)~(0x03u | RFS_REPLAY_CFG_FIT_EARLY)) != 0u) {
        return "CFG target byte has an unknown flag bit";
    }
    if (rec->u.cfg.target > (uint8_t)RFS_APP_TARGET_BRIDGE) {
        return "CFG target out of range";
    }
    uint8_t i = 14u;
    for (; i < n && p[i] != 0u; i++) {
        if (p[i] <= 0x20u || p[i] >= 0x7Fu || i - 14u >= RFS_REPLAY_MODEL_NAME_MAX) {
            return "CFG model name not printable or too long";
        }
        rec->u.cfg.model[i - 14u] = (char)p[i];
    }
    if (i == n) {
        return NULL;
    }
    /* The choice: the NUL, strategy, p0_min, the CONFIG frame's ranges (its length first:
     * a NUL near the end leaves no p0_min to read). */
    if (n - i != RFS_REPLAY_CHOICE_LEN) {
        return "CFG choice malformed or out of range";
    }
    const int16_t p0 = (int16_t)rd16(p + i + 2u);
    if (p[i + 1u] >= (uint8_t)RFS_SEEK_STRATEGY_COUNT ||
        (p0 != RFS_CAN_P0_NONE && (p0 < RFS_CAN_P0_MIN || p0 > RFS_CAN_P0_MAX))) {
        return "CFG choice malformed or out of range";
    }
    rec->u.cfg.chosen = true;
    rec->u.cfg.strategy = p[i + 1u];
    rec->u.cfg.p0_min = p0;
    return NULL;
}

/* A MAP payload into rec: NULL, or why it is malformed. */
static const char *get_map(const uint8_t *p, rfs_replay_rec_t *rec)
{
    rec->u.map.w = rd16(p);
    rec->u.map.h = rd16(p + 2);
    rec->u.map.res = rds32(p + 4);
    rec->u.map.origin_x = rds32(p + 8);
    rec->u.map.origin_y = rds32(p + 12);
    rec->u.map.has_wall = p[16];
    if (rec->u.map.w == 0u || rec->u.map.h == 0u) {
        return "MAP size is zero";
    }
    if (rec->u.map.res <= 0) {
        return "MAP resolution not positive";
    }
    if (rec->u.map.has_wall > 1u) {
        return "MAP has_wall not 0 or 1";
    }
    return NULL;
}

/* A CAN or CAN_TX payload into rec: NULL, or why it is malformed. */
static const char *get_can(const uint8_t *p, rfs_replay_rec_t *rec)
{
    rec->t_us = rds64(p);
    rec->u.can.id = rd32(p + 8);
    rec->u.can.dlc = p[12];
    memcpy(rec->u.can.data, p + 13, 8);
    if (rec->u.can.dlc > 8u) {
        return "CAN dlc over 8";
    }
    if (rec->u.can.id > 0x7FFu) {
        return "CAN id not 11-bit";
    }
    return NULL;
}

/* An OUT payload into rec: NULL, or why it is malformed. */
static const char *get_out(const uint8_t *p, rfs_replay_rec_t *rec)
{
    rec->t_us = rds64(p);
    rec->u.out.t_us = rec->t_us;
    rec->u.out.left_mm_s = (int16_t)rd16(p + 8);
    rec->u.out.right_mm_s = (int16_t)rd16(p + 10);
    rec->u.out.state = (rfs_seek_state_t)p[12];
    rec->u.out.faults = rd16(p + 13);
    rec->u.out.decided = p[15] != 0u;
    if (p[12] > (uint8_t)RFS_SEEK_DRIVING || p[15] > 1u) {
        return "OUT state or decided out of range";
    }
    return NULL;
}

/* The payload p (n bytes, its length checked) of a record of this type into rec: NULL,
 * or why it is malformed. */
static const char *get_payload(uint8_t type, const uint8_t *p, uint8_t n, rfs_replay_rec_t *rec)
{
    switch (type) {
    case RFS_REPLAY_CFG:
        return get_cfg(p, n, rec);
    case RFS_REPLAY_MAP:
        return get_map(p, rec);
    case RFS_REPLAY_MAP_FREE:
    case RFS_REPLAY_MAP_WALL:
        rec->u.chunk.offset = rd32(p);
        rec->u.chunk.n = (uint8_t)(n - 4u);
        memcpy(rec->u.chunk.bytes, p + 4, rec->u.chunk.n);
        return NULL;
    case RFS_REPLAY_POSE:
        rec->t_us = rds64(p);
        rec->u.pose.t_us = rds64(p + 8);
        rec->u.pose.x = rds32(p + 16);
        rec->u.pose.y = rds32(p + 20);
        rec->u.pose.theta = rds32(p + 24);
        return NULL;
    case RFS_REPLAY_RSSI:
        rec->t_us = rds64(p);
        rec->u.rssi.t_us = rds64(p + 8);
        rec->u.rssi.src = p[16];
        rec->u.rssi.dbm = (int8_t)p[17];
        return NULL;
    case RFS_REPLAY_RECEIVER:
        rec->t_us = rds64(p);
        rec->u.receiver_t_us = rds64(p + 8);
        return NULL;
    case RFS_REPLAY_CAN:
    case RFS_REPLAY_CAN_TX:
        return get_can(p, rec);
    case RFS_REPLAY_STEP:
    case RFS_REPLAY_RESET:
        rec->t_us = rds64(p);
        return NULL;
    case RFS_REPLAY_BUS:
        rec->t_us = rds64(p);
        rec->u.bus_off = p[8];
        return p[8] > 1u ? "BUS state not 0 or 1" : NULL;
    case RFS_REPLAY_END:
        return NULL;
    case RFS_REPLAY_OUT:
        return get_out(p, rec);
    case RFS_REPLAY_DECISION:
        get_decision(p, &rec->u.out.decision);
        rec->t_us = rec->u.out.decision.t_us;
        if (p[12] > (uint8_t)RFS_SEEK_EPSILON || p[13] > 15u ||
            p[14] > (uint8_t)RFS_DRIVE_BLOCKED) {
            return "DECISION kind, flags or previous status out of range";
        }
        return NULL;
    default:
        return "unknown record type";
    }
}

rfs_replay_status_t rfs_replay_parse(const uint8_t *buf, uint32_t len, uint32_t *used,
                                     rfs_replay_rec_t *rec)
{
    memset(rec, 0, sizeof *rec);
    if (len < 2u) {
        return RFS_REPLAY_NEED_MORE;
    }
    const uint8_t type = buf[0];
    const uint8_t n = buf[1];
    const char *why = check_length(type, n);
    if (why != NULL) {
        return bad(rec, why);
    }
    if (len < 2u + (uint32_t)n) {
        return RFS_REPLAY_NEED_MORE;
    }
    rec->type = (rfs_replay_type_t)type;
    why = get_payload(type, buf + 2, n, rec);
    if (why != NULL) {
        return bad(rec, why);
    }
    *used = 2u + n;
    return RFS_REPLAY_OK;
}

uint32_t rfs_replay_encode(const rfs_replay_rec_t *rec, uint8_t *buf, uint32_t cap)
{
    uint8_t tmp[RFS_REPLAY_MAX_RECORD];
    uint8_t *p = tmp + 2;
    switch (rec->type) {
    case RFS_REPLAY_CFG:
        if (rec->u.cfg.target > (uint8_t)RFS_APP_TARGET_BRIDGE) {
            return 0; /* out of range, or its high bits would read as flags */
        }
        p = wr64(p, rec->u.cfg.seed);
        *p++ = (uint8_t)(rec->u.cfg.target | (rec->u.cfg.fit_early ? RFS_REPLAY_CFG_FIT_EARLY : 0u));
        *p++ = rec->u.cfg.node;
        p = wr32(p, rec->u.cfg.fit_budget);
        for (uint32_t i = 0; i < RFS_REPLAY_MODEL_NAME_MAX && rec->u.cfg.model[i] != '\0'; i++) {
            *p++ = (uint8_t)rec->u.cfg.model[i];
        }
        if (rec->u.cfg.chosen) {
            *p++ = 0u;
            *p++ = rec->u.cfg.strategy;
            p = wr16(p, (uint16_t)rec->u.cfg.p0_min);
        }
        break;
    case RFS_REPLAY_MAP:
        p = wr16(p, rec->u.map.w);
        p = wr16(p, rec->u.map.h);
        p = wr32(p, (uint32_t)rec->u.map.res);
        p = wr32(p, (uint32_t)rec->u.map.origin_x);
        p = wr32(p, (uint32_t)rec->u.map.origin_y);
        *p++ = rec->u.map.has_wall;
        break;
    case RFS_REPLAY_MAP_FREE:
    case RFS_REPLAY_MAP_WALL:
        if (rec->u.chunk.n == 0u || rec->u.chunk.n > RFS_REPLAY_CHUNK) {
            return 0;
        }
        p = wr32(p, rec->u.chunk.offset);
        memcpy(p, rec->u.chunk.bytes, rec->u.chunk.n);
        p += rec->u.chunk.n;
        break;
    case RFS_REPLAY_POSE:
        p = wr64(p, (uint64_t)rec->t_us);
        p = wr64(p, (uint64_t)rec->u.pose.t_us);
        p = wr32(p, (uint32_t)rec->u.pose.x);
        p = wr32(p, (uint32_t)rec->u.pose.y);
        p = wr32(p, (uint32_t)rec->u.pose.theta);
        break;
    case RFS_REPLAY_RSSI:
        p = wr64(p, (uint64_t)rec->t_us);
        p = wr64(p, (uint64_t)rec->u.rssi.t_us);
        *p++ = rec->u.rssi.src;
        *p++ = (uint8_t)rec->u.rssi.dbm;
        break;
    case RFS_REPLAY_RECEIVER:
        p = wr64(p, (uint64_t)rec->t_us);
        p = wr64(p, (uint64_t)rec->u.receiver_t_us);
        break;
    case RFS_REPLAY_CAN:
    case RFS_REPLAY_CAN_TX:
        p = wr64(p, (uint64_t)rec->t_us);
        p = wr32(p, rec->u.can.id);
        *p++ = rec->u.can.dlc;
        memcpy(p, rec->u.can.data, 8);
        p += 8;
        break;
    case RFS_REPLAY_STEP:
    case RFS_REPLAY_RESET:
        p = wr64(p, (uint64_t)rec->t_us);
        break;
    case RFS_REPLAY_BUS:
        p = wr64(p, (uint64_t)rec->t_us);
        *p++ = rec->u.bus_off;
        break;
    case RFS_REPLAY_END:
        break;
    case RFS_REPLAY_OUT:
        p = wr64(p, (uint64_t)rec->u.out.t_us);
        p = wr16(p, (uint16_t)rec->u.out.left_mm_s);
        p = wr16(p, (uint16_t)rec->u.out.right_mm_s);
        *p++ = (uint8_t)rec->u.out.state;
        p = wr16(p, rec->u.out.faults);
        *p++ = rec->u.out.decided ? 1u : 0u;
        break;
    case RFS_REPLAY_DECISION:
        p = put_decision(p, &rec->u.out.decision);
        break;
    default:
        return 0;
    }
    const uint32_t n = (uint32_t)(p - tmp);
    const int want = payload_len((uint8_t)rec->type);
    if ((want >= 0 && n - 2u != (uint32_t)want) || n > cap) {
        return 0;
    }
    tmp[0] = (uint8_t)rec->type;
    tmp[1] = (uint8_t)(n - 2u);
    memcpy(buf, tmp, n);
    return n;
}

uint32_t rfs_replay_encode_out(const rfs_app_out_t *out, uint8_t *buf, uint32_t cap)
{
    rfs_replay_rec_t rec;
    memset(&rec, 0, sizeof rec);
    rec.type = RFS_REPLAY_OUT;
    rec.u.out = *out;
    uint32_t n = rfs_replay_encode(&rec, buf, cap);
    if (n == 0u || !out->decided) {
        return n;
    }
    rec.type = RFS_REPLAY_DECISION;
    const uint32_t m = rfs_replay_encode(&rec, buf + n, cap - n);
    return m == 0u ? 0u : n + m;
}

void rfs_replay_player_init(rfs_replay_player_t *p, rfs_app_t *app, const rfs_app_cfg_t *cfg,
                            rfs_replay_write_fn write, void *write_ctx)
{
    memset(p, 0, offsetof(rfs_replay_player_t, free_bits));
    p->app = app;
    p->cfg = *cfg;
    /* CONFIG frames in a stream may choose any registered model: the state buffer decides
     * what an image holds, as for a CFG's model name. */
    for (uint8_t k = 0; k < (uint8_t)RFS_CAN_NMODELS; k++) {
        p->cfg.models[k] = rfs_models_lookup(rfs_can_model_name(k));
    }
    p->write = write;
    p->write_ctx = write_ctx;
    uint8_t h[RFS_REPLAY_HEADER_LEN];
    rfs_replay_header(h);
    write(write_ctx, h, sizeof h);
}

static bool fail(rfs_replay_player_t *p, rfs_replay_err_t e)
{
    p->error = e;
    return false;
}

static bool start(rfs_replay_player_t *p)
{
    if (p->started) {
        return true;
    }
    if (!p->have_map) {
        return fail(p, RFS_REPLAY_E_NO_MAP);
    }
    if (rfs_app_init(p->app, &p->cfg, &p->map) != 0) {
        return fail(p, RFS_REPLAY_E_INIT);
    }
    p->started = true;
    return true;
}

bool rfs_replay_map_records(const rfs_app_map_t *m, rfs_replay_rec_fn fn, void *ctx)
{
    rfs_replay_rec_t r;
    memset(&r, 0, sizeof r);
    r.type = RFS_REPLAY_MAP;
    r.u.map.w = m->w;
    r.u.map.h = m->h;
    r.u.map.res = m->res;
    r.u.map.origin_x = m->origin_x;
    r.u.map.origin_y = m->origin_y;
    r.u.map.has_wall = m->wall != NULL ? 1u : 0u;
    if (!fn(ctx, &r)) {
        return false;
    }
    const uint32_t bytes = rfs_map_bytes(m->w, m->h);
    for (int g = 0; g < 2; g++) {
        const uint8_t *bits = g == 0 ? m->free : m->wall;
        if (bits == NULL) {
            continue;
        }
        for (uint32_t off = 0; off < bytes; off += RFS_REPLAY_CHUNK) {
            memset(&r, 0, sizeof r);
            r.type = g == 0 ? RFS_REPLAY_MAP_FREE : RFS_REPLAY_MAP_WALL;
            r.u.chunk.offset = off;
            r.u.chunk.n = (uint8_t)(bytes - off < RFS_REPLAY_CHUNK ? bytes - off : RFS_REPLAY_CHUNK);
            memcpy(r.u.chunk.bytes, bits + off, r.u.chunk.n);
            if (!fn(ctx, &r)) {
                return false;
            }
        }
    }
    return true;
}

static void emit_step(rfs_replay_player_t *p, int64_t now_us)
{
    rfs_app_out_t out;
    rfs_app_step(p->app, now_us, &out);
    rfs_app_background_all(p->app);
    uint8_t buf[2u * RFS_REPLAY_MAX_RECORD];
    uint32_t n = rfs_replay_encode_out(&out, buf, sizeof buf);
    p->write(p->write_ctx, buf, n);
    rfs_can_frame_t f[2];
    const uint8_t nf = rfs_app_frames(p->app, &out, f);
    if (p->app->bus_off) {
        return; /* the controller cannot send; the frames are not on the bus */
    }
    for (uint8_t i = 0; i < nf; i++) {
        rfs_replay_rec_t rec;
        memset(&rec, 0, sizeof rec);
        rec.type = RFS_REPLAY_CAN_TX;
        rec.t_us = now_us;
        rec.u.can.id = f[i].id;
        rec.u.can.dlc = f[i].dlc;
        memcpy(rec.u.can.data, f[i].data, 8);
        n = rfs_replay_encode(&rec, buf, sizeof buf);
        p->write(p->write_ctx, buf, n);
    }
}

bool rfs_replay_play(rfs_replay_player_t *p, const rfs_replay_rec_t *rec)
{
    if (p->error != RFS_REPLAY_E_NONE) {
        return false;
    }
    switch (rec->type) {
    case RFS_REPLAY_CFG:
        if (p->started) {
            return fail(p, RFS_REPLAY_E_ORDER);
        }
        p->cfg.seed = rec->u.cfg.seed;
        p->cfg.target = (rfs_app_target_t)rec->u.cfg.target;
        p->cfg.node_id = rec->u.cfg.node;
        p->cfg.seek.fit_budget = rec->u.cfg.fit_budget;
        p->cfg.seek.fit_early = rec->u.cfg.fit_early;
        if (rec->u.cfg.model[0] != '\0') {
            p->cfg.model = rfs_models_lookup(rec->u.cfg.model);
            if (p->cfg.model == NULL) {
                return fail(p, RFS_REPLAY_E_MODEL);
            }
            if (!rfs_app_model_fits(&p->cfg)) {
                return fail(p, RFS_REPLAY_E_MODEL_SIZE);
            }
        }
        if (rec->u.cfg.chosen &&
            rfs_app_cfg_choose(&p->cfg, p->cfg.target, (rfs_seek_strategy_t)rec->u.cfg.strategy,
                               p->cfg.model, rfs_can_p0_to_q16(rec->u.cfg.p0_min)) != 0) {
            return fail(p, RFS_REPLAY_E_CHOICE);
        }
        return true;
    case RFS_REPLAY_MAP:
        if (p->started) {
            return fail(p, RFS_REPLAY_E_ORDER);
        }
        if (rfs_map_bytes(rec->u.map.w, rec->u.map.h) > RFS_APP_MAX_MAP_BYTES) {
            return fail(p, RFS_REPLAY_E_MAP_SIZE);
        }
        p->map.w = rec->u.map.w;
        p->map.h = rec->u.map.h;
        p->map.res = rec->u.map.res;
        p->map.origin_x = rec->u.map.origin_x;
        p->map.origin_y = rec->u.map.origin_y;
        p->map.free = p->free_bits;
        p->map.wall = rec->u.map.has_wall ? p->wall_bits : NULL;
        memset(p->free_bits, 0, sizeof p->free_bits);
        memset(p->wall_bits, 0, sizeof p->wall_bits);
        p->have_map = true;
        return true;
    case RFS_REPLAY_MAP_FREE:
    case RFS_REPLAY_MAP_WALL: {
        if (!p->have_map || p->started) {
            return fail(p, RFS_REPLAY_E_CHUNK);
        }
        const uint32_t bytes = rfs_map_bytes(p->map.w, p->map.h);
        if (rec->u.chunk.offset > bytes || rec->u.chunk.n > bytes - rec->u.chunk.offset) {
            return fail(p, RFS_REPLAY_E_CHUNK);
        }
        uint8_t *dst = rec->type == RFS_REPLAY_MAP_FREE ? p->free_bits : p->wall_bits;
        memcpy(dst + rec->u.chunk.offset, rec->u.chunk.bytes, rec->u.chunk.n);
        return true;
    }
    case RFS_REPLAY_POSE:
        if (!start(p)) {
            return false;
        }
        (void)rfs_app_on_pose(p->app, &rec->u.pose, rec->t_us);
        return true;
    case RFS_REPLAY_RSSI:
        if (!start(p)) {
            return false;
        }
        (void)rfs_app_on_rssi(p->app, rec->u.rssi.src, rec->u.rssi.t_us, rec->u.rssi.dbm,
                              rec->t_us);
        return true;
    case RFS_REPLAY_RECEIVER:
        if (!start(p)) {
            return false;
        }
        (void)rfs_app_on_receiver(p->app, rec->u.receiver_t_us, rec->t_us);
        return true;
    case RFS_REPLAY_CAN: {
        if (!start(p)) {
            return false;
        }
        rfs_can_frame_t f;
        f.id = rec->u.can.id;
        f.dlc = rec->u.can.dlc;
        memcpy(f.data, rec->u.can.data, 8);
        (void)rfs_app_on_can(p->app, &f, rec->t_us);
        return true;
    }
    case RFS_REPLAY_STEP:
        if (!start(p)) {
            return false;
        }
        emit_step(p, rec->t_us);
        p->steps++;
        return true;
    case RFS_REPLAY_BUS:
        if (!start(p)) {
            return false;
        }
        rfs_app_set_bus_off(p->app, rec->u.bus_off != 0u);
        return true;
    case RFS_REPLAY_RESET:
        /* A watchdog reset: every byte of RAM state is lost, the image boots again. */
        p->started = false;
        p->resets++;
        return start(p);
    case RFS_REPLAY_END:
        return true;
    default:
        return fail(p, RFS_REPLAY_E_ORDER);
    }
}

const char *rfs_replay_err_str(rfs_replay_err_t e)
{
    switch (e) {
    case RFS_REPLAY_E_NONE: return "no error";
    case RFS_REPLAY_E_MAP_SIZE: return "MAP larger than the image holds";
    case RFS_REPLAY_E_CHUNK: return "map chunk outside the grid or before MAP";
    case RFS_REPLAY_E_NO_MAP: return "input before the map";
    case RFS_REPLAY_E_INIT: return "application rejected the map or configuration";
    case RFS_REPLAY_E_ORDER: return "record out of place in an input stream";
    case RFS_REPLAY_E_MODEL: return "CFG names an unknown model";
    case RFS_REPLAY_E_MODEL_SIZE: return "CFG model's state is larger than the image holds";
    case RFS_REPLAY_E_CHOICE: return "CFG chooses a strategy, model and target the image does not hold";
    default: return "unknown error";
    }
}
