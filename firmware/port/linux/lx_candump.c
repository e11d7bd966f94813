/* lx_candump.c - candump -L log lines written and read (lx_candump.h). */
#include "lx_candump.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

bool lx_candump_ifname_ok(const char *name)
{
    size_t n = 0;
    for (; name[n] != '\0'; n++) {
        const char c = name[n];
        if (n == LX_CANDUMP_IFNAME_MAX || c <= ' ' || c > '~' || c == '(' || c == '#') {
            return false;
        }
    }
    return n > 0;
}

size_t lx_candump_format(char *buf, size_t cap, int64_t t_us, const char *ifname, const rfs_can_frame_t *f)
{
    static const char hex[] = "0123456789ABCDEF";
    if (t_us < 0 || f->id > RFS_CAN_ID_MAX || f->dlc > 8u) {
        return 0;
    }
    /* candump's own form: "(%010ld.%06ld) %s %03X#" and the bytes as %02X. */
    const int n = snprintf(buf, cap, "(%010lld.%06lld) %s %03X#", (long long)(t_us / 1000000),
                           (long long)(t_us % 1000000), ifname, (unsigned)f->id);
    if (n < 0 || (size_t)n + 2u * f->dlc + 2u > cap) {
        return 0;
    }
    size_t k = (size_t)n;
    for (unsigned i = 0; i < f->dlc; i++) {
        buf[k++] = hex[f->data[i] >> 4];
        buf[k++] = hex[f->data[i] & 15u];
    }
    buf[k++] = '\n';
    buf[k] = '\0';
    return k;
}

static int hexval(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    return -1;
}

static int bad(const char **why, const char *reason)
{
    *why = reason;
    return -1;
}

/* "(SECONDS.UUUUUU)" at s[*i]: the time into rec, *i past the ')'. */
static int parse_time(const char *s, size_t len, size_t *i, lx_candump_rec_t *rec, const char **why)
{
    size_t k = *i;
    if (k >= len || s[k] != '(') {
        return bad(why, "no '(' opening the timestamp");
    }
    k++;
    int64_t sec = 0;
    unsigned digits = 0;
    for (; k < len && s[k] >= '0' && s[k] <= '9'; k++, digits++) {
        if (digits == 12u) {
            return bad(why, "timestamp: more than 12 digits of seconds");
        }
        sec = sec * 10 + (s[k] - '0');
    }
    if (digits == 0u) {
        return bad(why, "timestamp: seconds expected after '('");
    }
    if (k + 8u > len || s[k] != '.' || s[k + 7u] != ')') {
        return bad(why, "timestamp: '.', 6 digits of microseconds and ')' expected");
    }
    int64_t usec = 0;
    for (size_t d = k + 1u; d < k + 7u; d++) {
        if (s[d] < '0' || s[d] > '9') {
            return bad(why, "timestamp: '.', 6 digits of microseconds and ')' expected");
        }
        usec = usec * 10 + (s[d] - '0');
    }
    rec->t_us = sec * 1000000 + usec; /* at most 10^18 + 10^6: no overflow */
    *i = k + 8u;
    return 0;
}

/* The identifier, up to its '#', at s[*i]: id, ext and kind into rec. */
static int parse_id(const char *s, size_t len, size_t *i, lx_candump_rec_t *rec, const char **why)
{
    size_t k = *i;
    uint32_t v = 0;
    unsigned digits = 0;
    for (; k < len && hexval(s[k]) >= 0; k++, digits++) {
        if (digits < 8u) {
            v = v << 4 | (uint32_t)hexval(s[k]);
        }
    }
    if (digits != 3u && digits != 8u) {
        return bad(why, "identifier: 3 hex digits (11-bit) or 8 (29-bit) expected");
    }
    if (k >= len || s[k] != '#') {
        return bad(why, "'#' expected after the identifier");
    }
    if (digits == 3u && v > RFS_CAN_ID_MAX) {
        return bad(why, "identifier: an 11-bit one is at most 7FF");
    }
    if (digits == 8u && v > 0x3FFFFFFFu) {
        return bad(why, "identifier: a 29-bit one is at most 1FFFFFFF (20000000 marks an error frame)");
    }
    rec->ext = digits == 8u;
    /* candump writes an error frame as its 8-digit id with the error flag (bit 29). */
    rec->kind = (v & 0x20000000u) != 0u ? LX_CANDUMP_ERROR : LX_CANDUMP_DATA;
    rec->id = v & 0x1FFFFFFFu;
    *i = k + 1u;
    return 0;
}

/* The frame's data after its '#' at s[*i] (stops at a space or the end). */
static int parse_data(const char *s, size_t len, size_t *i, lx_candump_rec_t *rec, const char **why)
{
    size_t k = *i;
    if (k < len && s[k] == '#') {
        return bad(why, "CAN FD frame ('##'): only classic CAN is read");
    }
    if (k < len && s[k] == 'R') {
        rec->kind = LX_CANDUMP_REMOTE;
        k++;
        if (k < len && s[k] >= '0' && s[k] <= '8') {
            rec->dlc = (uint8_t)(s[k++] - '0');
        }
        *i = k;
        return 0;
    }
    while (k < len && s[k] != ' ') {
        if (s[k] == '.' && rec->dlc > 0u) { /* can-utils' optional byte separator */
            k++;
            continue;
        }
        if (s[k] == '_') {
            return bad(why, "a raw DLC over 8 ('_' suffix) is not read");
        }
        const int hi = hexval(s[k]), lo = k + 1u < len ? hexval(s[k + 1u]) : -1;
        if (hi < 0 || lo < 0) {
            return bad(why, "data: hex digits in pairs expected");
        }
        if (rec->dlc == 8u) {
            return bad(why, "data: more than 8 bytes");
        }
        rec->data[rec->dlc++] = (uint8_t)(hi << 4 | lo);
        k += 2u;
    }
    *i = k;
    return 0;
}

int lx_candump_parse(const char *s, size_t len, lx_candump_rec_t *rec, const char **why)
{
    memset(rec, 0, sizeof *rec);
    if (len > 0u && s[len - 1u] == '\r') {
        len--;
    }
    if (len > LX_CANDUMP_LINE_MAX) {
        return bad(why, "line longer than 200 characters");
    }
    size_t i = 0;
    if (parse_time(s, len, &i, rec, why) != 0) {
        return -1;
    }
    if (i >= len || s[i] != ' ') {
        return bad(why, "a space and the interface expected after the timestamp");
    }
    while (i < len && s[i] == ' ') { /* candump right-aligns the names of several interfaces */
        i++;
    }
    size_t n = 0;
    for (; i < len && s[i] != ' '; i++, n++) {
        if (n == LX_CANDUMP_IFNAME_MAX) {
            return bad(why, "interface name longer than 15 characters");
        }
        if (s[i] < ' ' || s[i] > '~' || s[i] == '(' || s[i] == '#') {
            return bad(why, "interface name: a control character, '(' or '#'");
        }
        rec->ifname[n] = s[i];
    }
    if (n == 0u || i >= len) {
        return bad(why, "interface name and frame expected after the timestamp");
    }
    while (i < len && s[i] == ' ') {
        i++;
    }
    if (parse_id(s, len, &i, rec, why) != 0 || parse_data(s, len, &i, rec, why) != 0) {
        return -1;
    }
    if (i < len) {
        /* candump -x: the direction after the frame, one letter. */
        while (i < len && s[i] == ' ') {
            i++;
        }
        if (i + 1u != len || (s[i] != 'R' && s[i] != 'T')) {
            return bad(why, "unexpected text after the frame");
        }
    }
    return 0;
}

struct lx_candump {
    FILE *f;
    char *path;   /* the log's name */
    char *tmp;    /* where it is written until renamed */
    char ifname[LX_CANDUMP_IFNAME_MAX + 1u];
    uint64_t n;   /* frames written */
    int64_t shift_us; /* added to every time: 0, or LX_CANDUMP_SHIFT_US (set by the first frame) */
    const char *failed; /* the first reason a frame was lost, or NULL */
};

lx_candump_t *lx_candump_open(const char *path, const char *ifname, char *err, size_t errlen)
{
    if (!lx_candump_ifname_ok(ifname)) {
        snprintf(err, errlen, "%s: interface name '%s': 1 to 15 characters, no space, '(' or '#'", path, ifname);
        return NULL;
    }
    lx_candump_t *w = calloc(1, sizeof *w);
    const size_t n = strlen(path) + 32u;
    if (w == NULL || (w->path = strdup(path)) == NULL || (w->tmp = malloc(n)) == NULL) {
        snprintf(err, errlen, "%s: out of memory", path);
        (void)lx_candump_close(w, false, NULL, 0);
        return NULL;
    }
    snprintf(w->tmp, n, "%s.tmp.%ld", path, (long)getpid());
    snprintf(w->ifname, sizeof w->ifname, "%s", ifname);
    w->f = fopen(w->tmp, "w");
    if (w->f == NULL) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        (void)lx_candump_close(w, false, NULL, 0);
        return NULL;
    }
    return w;
}

void lx_candump_write(lx_candump_t *w, int64_t t_us, const rfs_can_frame_t *f)
{
    char line[LX_CANDUMP_FMT_MAX];
    if (w->n == 0u && w->failed == NULL && t_us >= 0 && t_us < LX_CANDUMP_SHIFT_US) {
        w->shift_us = LX_CANDUMP_SHIFT_US;
    }
    const size_t n = lx_candump_format(line, sizeof line, t_us > INT64_MAX - w->shift_us ? -1 : t_us + w->shift_us,
                                       w->ifname, f);
    if (n == 0u) {
        if (w->failed == NULL) {
            w->failed = "a frame has a time before the epoch or is not a classic 11-bit frame";
        }
        return;
    }
    if (fwrite(line, 1, n, w->f) != n && w->failed == NULL) {
        w->failed = strerror(errno);
    }
    w->n++;
}

uint64_t lx_candump_count(const lx_candump_t *w)
{
    return w->n;
}

int lx_candump_close(lx_candump_t *w, bool keep, char *err, size_t errlen)
{
    if (w == NULL) {
        return 0;
    }
    int rc = 0;
    if (w->f != NULL) {
        if ((fflush(w->f) != 0 || ferror(w->f)) && w->failed == NULL) {
            w->failed = strerror(errno);
        }
        if (fclose(w->f) != 0 && w->failed == NULL) {
            w->failed = strerror(errno);
        }
        if (keep && w->failed == NULL && rename(w->tmp, w->path) != 0) {
            w->failed = strerror(errno);
        }
        if (keep && w->failed != NULL) {
            snprintf(err, errlen, "%s: write failed: %s", w->path, w->failed);
            rc = -1;
        }
        if (!keep || rc != 0) {
            (void)remove(w->tmp);
        }
    }
    free(w->path);
    free(w->tmp);
    free(w);
    return rc;
}
