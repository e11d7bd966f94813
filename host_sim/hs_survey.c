/* hs_survey.c - the transmitters of an 802.11 capture (hs_survey.h). */
#include "hs_survey.h"

#include <stdlib.h>
#include <string.h>

#include "lx_radiotap.h"

typedef struct tx {
    uint8_t mac[6];
    uint8_t ssid_len;
    bool has_ssid;
    uint8_t ssid[LX_WLAN_SSID_MAX];
    uint64_t frames, dbm_frames;
    int64_t dbm_sum;
    int dbm_min, dbm_max;
    uint64_t first_sec, last_sec;
    uint32_t first_nsec, last_nsec;
} tx_t;

struct hs_survey {
    tx_t *v;          /* the transmitters in the order first seen */
    size_t n, cap;
    uint32_t *slot;   /* open addressing over v: index + 1, 0 = empty; nslot a power of 2 */
    size_t nslot;
};

hs_survey_t *hs_survey_new(void)
{
    return calloc(1, sizeof(hs_survey_t));
}

void hs_survey_free(hs_survey_t *s)
{
    if (s != NULL) {
        free(s->v);
        free(s->slot);
        free(s);
    }
}

/* FNV-1a of the address. */
static size_t mac_hash(const uint8_t *mac)
{
    uint32_t h = 2166136261u;
    for (int i = 0; i < 6; i++) {
        h = (h ^ mac[i]) * 16777619u;
    }
    return h;
}

/* The slot of mac: its transmitter's or the empty one where it would go. */
static size_t find(const hs_survey_t *s, const uint8_t *mac)
{
    size_t i = mac_hash(mac) & (s->nslot - 1u);
    while (s->slot[i] != 0u && memcmp(s->v[s->slot[i] - 1u].mac, mac, 6) != 0) {
        i = (i + 1u) & (s->nslot - 1u);
    }
    return i;
}

/* Room for one more transmitter, the table at most half full: 0, or -1. */
static int grow(hs_survey_t *s)
{
    if (s->n == s->cap) {
        const size_t cap = s->cap ? s->cap * 2u : 64u;
        tx_t *v = realloc(s->v, cap * sizeof *v);
        if (v == NULL) {
            return -1;
        }
        s->v = v;
        s->cap = cap;
    }
    if (2u * (s->n + 1u) > s->nslot) {
        const size_t nslot = s->nslot ? s->nslot * 2u : 128u;
        uint32_t *slot = calloc(nslot, sizeof *slot);
        if (slot == NULL) {
            return -1;
        }
        free(s->slot);
        s->slot = slot;
        s->nslot = nslot;
        for (size_t k = 0; k < s->n; k++) {
            s->slot[find(s, s->v[k].mac)] = (uint32_t)(k + 1u);
        }
    }
    return 0;
}

static bool time_before(uint64_t a_sec, uint32_t a_nsec, uint64_t b_sec, uint32_t b_nsec)
{
    return a_sec < b_sec || (a_sec == b_sec && a_nsec < b_nsec);
}

int hs_survey_add(hs_survey_t *s, const hs_survey_frame_t *f)
{
    if (s->n >= UINT32_MAX - 1u || grow(s) != 0) {
        return -1;
    }
    const size_t i = find(s, f->ta);
    tx_t *t;
    if (s->slot[i] == 0u) {
        t = &s->v[s->n];
        memset(t, 0, sizeof *t);
        memcpy(t->mac, f->ta, 6);
        t->first_sec = t->last_sec = f->sec;
        t->first_nsec = t->last_nsec = f->nsec;
        s->slot[i] = (uint32_t)++s->n;
    } else {
        t = &s->v[s->slot[i] - 1u];
    }
    t->frames++;
    if (time_before(f->sec, f->nsec, t->first_sec, t->first_nsec)) {
        t->first_sec = f->sec;
        t->first_nsec = f->nsec;
    }
    if (time_before(t->last_sec, t->last_nsec, f->sec, f->nsec)) {
        t->last_sec = f->sec;
        t->last_nsec = f->nsec;
    }
    if (f->has_dbm) {
        t->dbm_min = t->dbm_frames == 0u || f->dbm < t->dbm_min ? f->dbm : t->dbm_min;
        t->dbm_max = t->dbm_frames == 0u || f->dbm > t->dbm_max ? f->dbm : t->dbm_max;
        t->dbm_sum += f->dbm;
        t->dbm_frames++;
    }
    /* A hidden network's beacons carry an empty or all-zero SSID: keep looking. */
    bool named = false;
    for (size_t k = 0; f->ssid != NULL && k < f->ssid_len && k < LX_WLAN_SSID_MAX; k++) {
        named = named || f->ssid[k] != 0u;
    }
    if (named && !t->has_ssid) {
        t->ssid_len = (uint8_t)(f->ssid_len < LX_WLAN_SSID_MAX ? f->ssid_len : LX_WLAN_SSID_MAX);
        memcpy(t->ssid, f->ssid, t->ssid_len);
        t->has_ssid = true;
    }
    return 0;
}

uint64_t hs_survey_frames(const hs_survey_t *s, const uint8_t *mac)
{
    if (s->n == 0u) {
        return 0;
    }
    const size_t i = find(s, mac);
    return s->slot[i] != 0u ? s->v[s->slot[i] - 1u].frames : 0u;
}

/* Most frames first, ties by address. */
static int by_frames(const void *a, const void *b)
{
    const tx_t *x = a, *y = b;
    if (x->frames != y->frames) {
        return x->frames > y->frames ? -1 : 1;
    }
    return memcmp(x->mac, y->mac, 6);
}

static void write_row(const tx_t *t, FILE *out)
{
    fprintf(out, "%02x:%02x:%02x:%02x:%02x:%02x\t%llu\t%llu\t", t->mac[0], t->mac[1], t->mac[2], t->mac[3],
            t->mac[4], t->mac[5], (unsigned long long)t->frames, (unsigned long long)t->dbm_frames);
    if (t->dbm_frames > 0u) {
        fprintf(out, "%.2f\t%d\t%d\t", (double)t->dbm_sum / (double)t->dbm_frames, t->dbm_min, t->dbm_max);
    } else {
        fputs("\t\t\t", out);
    }
    fprintf(out, "%llu.%09u\t%llu.%09u\t", (unsigned long long)t->first_sec, (unsigned)t->first_nsec,
            (unsigned long long)t->last_sec, (unsigned)t->last_nsec);
    for (unsigned k = 0; t->has_ssid && k < t->ssid_len; k++) {
        const uint8_t c = t->ssid[k];
        if (c >= 0x20u && c <= 0x7Eu && c != '\\') {
            fputc(c, out);
        } else {
            fprintf(out, "\\x%02x", c);
        }
    }
    fputc('\n', out);
}

long hs_survey_write(const hs_survey_t *s, FILE *out)
{
    /* A sorted copy: the survey keeps its order, which its index points into. */
    tx_t *order = malloc((s->n ? s->n : 1u) * sizeof *order);
    if (order == NULL) {
        return -1;
    }
    if (s->n > 0u) {
        memcpy(order, s->v, s->n * sizeof *order);
    }
    qsort(order, s->n, sizeof *order, by_frames);
    fputs("mac\tframes\tdbm_frames\tmean_dbm\tmin_dbm\tmax_dbm\tfirst_epoch\tlast_epoch\tssid\n", out);
    for (size_t k = 0; k < s->n; k++) {
        write_row(&order[k], out);
    }
    free(order);
    return (long)s->n;
}
