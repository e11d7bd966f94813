/* rfs_replay.h - the recorded stream format: timestamped inputs in, outputs out.
 *
 * One format serves both directions, so the host build and the ARM image under qemu can
 * be fed the same bytes and their outputs compared byte for byte:
 *
 *   stream  = header record*
 *   header  = "RFSR" u16 version (1) u16 zero                      (8 bytes)
 *   record  = u8 type, u8 len, len bytes of payload                (all little-endian)
 *
 * Input records (times are the controller's clock, int64 microseconds):
 *   CFG      seed u64, target u8 (| 0x80: seek.fit_early), node u8, fit_budget u32,
 *            [model name, 1..15 bytes, no NUL: rfs_models.h],
 *            [0 u8, strategy u8, p0_min i16: a CONFIG frame's choice]   14..33
 *   MAP      w u16, h u16, res q16, origin_x q16, origin_y q16,
 *            has_wall u8                                               17
 *   MAP_FREE offset u32, 1..RFS_REPLAY_CHUNK bytes of the free grid    5..
 *   MAP_WALL offset u32, bytes of the wall grid                        5..
 *   POSE     rx i64, t i64, x q16, y q16, theta q16                    28
 *   RSSI     rx i64, t i64, src u8, dbm i8                             18
 *   CAN      rx i64, id u32, dlc u8, data[8]                           21
 *   RECEIVER rx i64, t i64  (receiver heartbeat: listening up to t,     16
 *                            docs/FAULTS.md)
 *   STEP     now i64                          (run one control period)  8
 *   BUS      now i64, off u8                  (bus-off entered / left)  9
 *   RESET    now i64                          (watchdog reset: re-init) 8
 *   END      (no payload)                                               0
 * Output records:
 *   OUT      t i64, left i16, right i16, state u8, faults u16, decided u8   16
 *   DECISION iteration u32, t i64, kind u8, flags u8, prev u8,
 *            prediction, mean, epsilon, x, y, goal_x, goal_y, max_x, max_y,
 *            path_len (q16 each), samples u16                           57
 *   CAN_TX   t i64, id u32, dlc u8, data[8]                             21
 *
 * Version 1 streams written before RECEIVER existed hold no such record and load unchanged;
 * a player fed none keeps the packets-only rule. A CFG without the choice after its NUL
 * (written before it existed) keeps the player's strategy and path-loss floor; one without
 * the fit_early bit (all before it) plays with fit_early off. Other target bits are refused.
 *
 * The parser is portable C (no libc but memcpy/memset), works on a caller buffer that
 * may end anywhere, checks every length, enum and range, and never reads past `len`.
 */
#ifndef RFS_REPLAY_H
#define RFS_REPLAY_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_app.h"
#include "rfs_fix.h"
#include "rfs_store.h"

/// Stream header bytes.
#define RFS_REPLAY_HEADER_LEN 8u
/// Format version.
#define RFS_REPLAY_VERSION 1u
/// Most grid bytes in one MAP_FREE / MAP_WALL record.
#define RFS_REPLAY_CHUNK 240u
/// Longest model name a CFG record carries, bytes (without the NUL).
#define RFS_REPLAY_MODEL_NAME_MAX 15u
/// Bytes of a CFG's choice: the NUL, strategy, p0_min.
#define RFS_REPLAY_CHOICE_LEN 4u
/// The CFG target byte's flag: seek.fit_early on (docs/FIRMWARE.md, "Learning between periods").
#define RFS_REPLAY_CFG_FIT_EARLY 0x80u
/// Longest encoded record (type, len, 255 bytes of payload).
#define RFS_REPLAY_MAX_RECORD 257u

/// Record types.
typedef enum rfs_replay_type {
    RFS_REPLAY_CFG = 0x01,
    RFS_REPLAY_MAP = 0x02,
    RFS_REPLAY_MAP_FREE = 0x03,
    RFS_REPLAY_MAP_WALL = 0x04,
    RFS_REPLAY_POSE = 0x10,
    RFS_REPLAY_RSSI = 0x11,
    RFS_REPLAY_CAN = 0x12,
    RFS_REPLAY_RECEIVER = 0x13,
    RFS_REPLAY_STEP = 0x20,
    RFS_REPLAY_BUS = 0x21,
    RFS_REPLAY_RESET = 0x22,
    RFS_REPLAY_END = 0x7F,
    RFS_REPLAY_OUT = 0x80,
    RFS_REPLAY_DECISION = 0x81,
    RFS_REPLAY_CAN_TX = 0x82,
} rfs_replay_type_t;

/// Result of parsing.
typedef enum rfs_replay_status {
    RFS_REPLAY_OK = 0,     ///< one record decoded
    RFS_REPLAY_NEED_MORE,  ///< the buffer ends inside a record: supply more bytes
    RFS_REPLAY_BAD,        ///< malformed record (see rfs_replay_rec_t.error)
} rfs_replay_status_t;

/// A raw CAN frame as recorded (the same layout as rfs_can_frame_t).
typedef struct rfs_replay_can {
    uint32_t id;      ///< 11-bit identifier
    uint8_t dlc;      ///< data length, 0..8
    uint8_t data[8];  ///< payload
} rfs_replay_can_t;

/// One decoded record.
typedef struct rfs_replay_rec {
    rfs_replay_type_t type;   ///< record type
    int64_t t_us;             ///< rx / step / output time, microseconds (0 for CFG, MAP, END)
    union {
        struct {
            uint64_t seed;    ///< random seed
            uint8_t target;   ///< rfs_app_target_t
            uint8_t node;     ///< node id
            uint32_t fit_budget; ///< the model's work units a control period (0 = all at once)
            bool fit_early;   ///< seek.fit_early (the target byte's RFS_REPLAY_CFG_FIT_EARLY)
            /// internal model by registry name, NUL-terminated; "" = the player's base
            /// configuration (the local ridge)
            char model[RFS_REPLAY_MODEL_NAME_MAX + 1u];
            bool chosen;      ///< the strategy and p0_min below are present
            uint8_t strategy; ///< rfs_seek_strategy_t (a CONFIG frame's Strategy)
            int16_t p0_min;   ///< path-loss floor, dBm / 128 or RFS_CAN_P0_NONE (P0Min)
        } cfg;                ///< CFG
        struct {
            uint16_t w, h;    ///< cells
            rfs_q16_t res;    ///< metres per cell, Q16.16
            rfs_q16_t origin_x, origin_y; ///< metres, Q16.16
            uint8_t has_wall; ///< 0 or 1
        } map;                ///< MAP
        struct {
            uint32_t offset;  ///< byte offset into the grid
            uint8_t n;        ///< bytes, 1..RFS_REPLAY_CHUNK
            uint8_t bytes[RFS_REPLAY_CHUNK]; ///< grid bytes
        } chunk;              ///< MAP_FREE, MAP_WALL
        rfs_pose_t pose;      ///< POSE (pose.t_us is the sender's time stamp)
        struct {
            int64_t t_us;     ///< when measured, microseconds
            uint8_t src;      ///< source index
            int8_t dbm;       ///< dBm
        } rssi;               ///< RSSI
        int64_t receiver_t_us; ///< RECEIVER: capture time listened up to, microseconds
        rfs_replay_can_t can; ///< CAN, CAN_TX
        uint8_t bus_off;      ///< BUS: 1 = entered bus-off, 0 = recovered
        rfs_app_out_t out;    ///< OUT (decision unused) and DECISION (decision only)
    } u;
    const char *error;        ///< static reason when BAD
} rfs_replay_rec_t;

/// Write the 8-byte stream header into buf.
void rfs_replay_header(uint8_t buf[RFS_REPLAY_HEADER_LEN]);

/// Check a stream header. Returns 0, or -1 (bad magic or version).
int rfs_replay_check_header(const uint8_t *buf, uint32_t len);

/// Decode the record at the start of buf[0..len). On OK, *used is its size in bytes.
rfs_replay_status_t rfs_replay_parse(const uint8_t *buf, uint32_t len, uint32_t *used,
                                     rfs_replay_rec_t *rec);

/// Encode a record into buf (cap >= RFS_REPLAY_MAX_RECORD is always enough). Returns
/// the bytes written, 0 when the record is invalid or does not fit.
uint32_t rfs_replay_encode(const rfs_replay_rec_t *rec, uint8_t *buf, uint32_t cap);

/// Encode a step's output: OUT, then DECISION when out->decided. Returns bytes written
/// (cap >= 2 * RFS_REPLAY_MAX_RECORD is always enough), 0 when it does not fit.
uint32_t rfs_replay_encode_out(const rfs_app_out_t *out, uint8_t *buf, uint32_t cap);

/// Takes one record (a recorder writing and playing it, a player, a printer); false stops.
typedef bool (*rfs_replay_rec_fn)(void *ctx, const rfs_replay_rec_t *rec);

/// Hand `fn` the records that carry a map: MAP, then the free grid and (when m->wall is
/// not NULL) the wall grid in MAP_FREE / MAP_WALL chunks of RFS_REPLAY_CHUNK bytes.
/// Returns false as soon as fn does.
bool rfs_replay_map_records(const rfs_app_map_t *m, rfs_replay_rec_fn fn, void *ctx);

/// Where a player writes its output bytes (a file, semihosting, a buffer).
typedef void (*rfs_replay_write_fn)(void *ctx, const uint8_t *p, uint32_t n);

/// Player errors (rfs_replay_player_t.error).
typedef enum rfs_replay_err {
    RFS_REPLAY_E_NONE = 0,
    RFS_REPLAY_E_MAP_SIZE,    ///< MAP larger than the compile-time maxima
    RFS_REPLAY_E_CHUNK,       ///< MAP_FREE / MAP_WALL outside the grid, or before MAP
    RFS_REPLAY_E_NO_MAP,      ///< an input record came before MAP and its grids
    RFS_REPLAY_E_INIT,        ///< rfs_app_init() rejected the map or configuration
    RFS_REPLAY_E_ORDER,       ///< an output record (or CFG/MAP after inputs) in an input stream
    RFS_REPLAY_E_MODEL,       ///< CFG names a model the registry does not know
    RFS_REPLAY_E_MODEL_SIZE,  ///< CFG names a model whose state the image cannot hold
    RFS_REPLAY_E_CHOICE,      ///< CFG chooses what the image does not hold (rfs_app_cfg_choose)
} rfs_replay_err_t;

/// Plays an input stream into an application: the one driver loop shared by the host
/// program and the emulator image, so both run the very same code. Caller-owned, ~20 KB
/// (the map grids) plus the application it points to.
typedef struct rfs_replay_player {
    rfs_app_t *app;                           ///< the application driven
    rfs_app_cfg_t cfg;                        ///< configuration (CFG overrides seed, target, node,
                                              ///< fit budget, fit_early, model, strategy, p0_min)
    rfs_app_map_t map;                        ///< map header (MAP), grids below
    bool have_map;                            ///< MAP seen
    bool started;                             ///< rfs_app_init() done
    rfs_replay_err_t error;                   ///< first error, playing stops
    uint32_t steps;                           ///< STEP records played
    uint32_t resets;                          ///< RESET records played
    rfs_replay_write_fn write;                ///< output sink
    void *write_ctx;                          ///< its context
    uint8_t free_bits[RFS_APP_MAX_MAP_BYTES]; ///< free grid, filled by MAP_FREE
    uint8_t wall_bits[RFS_APP_MAX_MAP_BYTES]; ///< wall grid, filled by MAP_WALL
} rfs_replay_player_t;

/// Start a player on `app` with the base configuration (CFG records override seed,
/// target, node id, fit budget, fit_early and, when they name one, the model: its state goes into
/// the base configuration's model_state buffer, or the application's built-in one; a
/// CFG's choice goes through rfs_app_cfg_choose(), as a CONFIG frame's). CONFIG frames may
/// choose every registered model (cfg.models), those whose state fits the buffer.
/// Writes the output stream header through `write`.
void rfs_replay_player_init(rfs_replay_player_t *p, rfs_app_t *app, const rfs_app_cfg_t *cfg,
                            rfs_replay_write_fn write, void *write_ctx);

/// Play one decoded input record: feed the application, and for STEP write OUT (+
/// DECISION) and, unless bus-off, the CAN_TX frames. Returns false once an error stopped
/// the player (p->error says which).
bool rfs_replay_play(rfs_replay_player_t *p, const rfs_replay_rec_t *rec);

/// Short constant description of a player error.
const char *rfs_replay_err_str(rfs_replay_err_t e);

#endif /* RFS_REPLAY_H */
