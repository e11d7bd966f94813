/* rfs_replay.c - the recorded stream format (see rfs_replay.h). Portable: only memcpy and
 * memset, explicit little-endian byte handling, every length checked before a read. */
#include "rfs_replay.h"

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
    case RFS_REPLAY_CFG: return 10;
    case RFS_REPLAY_MAP: return 17;
    case RFS_REPLAY_MAP_FREE:
    case RFS_REPLAY_MAP_WALL: return -1;
    case RFS_REPLAY_POSE: return 28;
    case RFS_REPLAY_RSSI: return 18;
    case RFS_REPLAY_CAN: return 21;
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

rfs_replay_status_t rfs_replay_parse(const uint8_t *buf, uint32_t len, uint32_t *used,
                                     rfs_replay_rec_t *rec)
{
    memset(rec, 0, sizeof *rec);
    if (len < 2u) {
        return RFS_REPLAY_NEED_MORE;
    }
    const uint8_t type = buf[0];
    const uint8_t n = buf[1];
    const int want = payload_len(type);
    if (want == -2) {
        return bad(rec, "unknown record type");
    }
    if (want >= 0 && n != (uint8_t)want) {
        return bad(rec, "wrong record length for its type");
    }
    if (want == -1 && (n < 5u || n > 4u + RFS_REPLAY_CHUNK)) {
        return bad(rec, "map chunk length out of range");
    }
    if (len < 2u + (uint32_t)n) {
        return RFS_REPLAY_NEED_MORE;
    }
    const uint8_t *p = buf + 2;
    rec->type = (rfs_replay_type_t)type;
    switch (type) {
    case RFS_REPLAY_CFG:
        rec->u.cfg.seed = rd64(p);
        rec->u.cfg.target = p[8];
        rec->u.cfg.node = p[9];
        if (rec->u.cfg.target > (uint8_t)RFS_APP_TARGET_BRIDGE) {
            return bad(rec, "CFG target out of range");
        }
        break;
    case RFS_REPLAY_MAP:
        rec->u.map.w = rd16(p);
        rec->u.map.h = rd16(p + 2);
        rec->u.map.res = rds32(p + 4);
        rec->u.map.origin_x = rds32(p + 8);
        rec->u.map.origin_y = rds32(p + 12);
        rec->u.map.has_wall = p[16];
        if (rec->u.map.w == 0u || rec->u.map.h == 0u) {
            return bad(rec, "MAP size is zero");
        }
        if (rec->u.map.res <= 0) {
            return bad(rec, "MAP resolution not positive");
        }
        if (rec->u.map.has_wall > 1u) {
            return bad(rec, "MAP has_wall not 0 or 1");
        }
        break;
    case RFS_REPLAY_MAP_FREE:
    case RFS_REPLAY_MAP_WALL:
        rec->u.chunk.offset = rd32(p);
        rec->u.chunk.n = (uint8_t)(n - 4u);
        memcpy(rec->u.chunk.bytes, p + 4, rec->u.chunk.n);
        break;
    case RFS_REPLAY_POSE:
        rec->t_us = rds64(p);
        rec->u.pose.t_us = rds64(p + 8);
        rec->u.pose.x = rds32(p + 16);
        rec->u.pose.y = rds32(p + 20);
        rec->u.pose.theta = rds32(p + 24);
        break;
    case RFS_REPLAY_RSSI:
        rec->t_us = rds64(p);
        rec->u.rssi.t_us = rds64(p + 8);
        rec->u.rssi.src = p[16];
        rec->u.rssi.dbm = (int8_t)p[17];
        break;
    case RFS_REPLAY_CAN:
    case RFS_REPLAY_CAN_TX:
        rec->t_us = rds64(p);
        rec->u.can.id = rd32(p + 8);
        rec->u.can.dlc = p[12];
        memcpy(rec->u.can.data, p + 13, 8);
        if (rec->u.can.dlc > 8u) {
            return bad(rec, "CAN dlc over 8");
        }
        if (rec->u.can.id > 0x7FFu) {
            return bad(rec, "CAN id not 11-bit");
        }
        break;
    case RFS_REPLAY_STEP:
    case RFS_REPLAY_RESET:
        rec->t_us = rds64(p);
        break;
    case RFS_REPLAY_BUS:
        rec->t_us = rds64(p);
        rec->u.bus_off = p[8];
        if (p[8] > 1u) {
            return bad(rec, "BUS state not 0 or 1");
        }
        break;
    case RFS_REPLAY_END:
        break;
    case RFS_REPLAY_OUT:
        rec->t_us = rds64(p);
        rec->u.out.t_us = rec->t_us;
        rec->u.out.left_mm_s = (int16_t)rd16(p + 8);
        rec->u.out.right_mm_s = (int16_t)rd16(p + 10);
        rec->u.out.state = (rfs_seek_state_t)p[12];
        rec->u.out.faults = rd16(p + 13);
        rec->u.out.decided = p[15] != 0u;
        if (p[12] > (uint8_t)RFS_SEEK_DRIVING || p[15] > 1u) {
            return bad(rec, "OUT state or decided out of range");
        }
        break;
    case RFS_REPLAY_DECISION:
        get_decision(p, &rec->u.out.decision);
        rec->t_us = rec->u.out.decision.t_us;
        if (p[12] > (uint8_t)RFS_SEEK_EPSILON || p[13] > 15u ||
            p[14] > (uint8_t)RFS_DRIVE_BLOCKED) {
            return bad(rec, "DECISION kind, flags or previous status out of range");
        }
        break;
    default:
        return bad(rec, "unknown record type");
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
        p = wr64(p, rec->u.cfg.seed);
        *p++ = rec->u.cfg.target;
        *p++ = rec->u.cfg.node;
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
