/* lx_can.c - SocketCAN behind firmware/port/linux/lx_can.h; the only file with <linux/can.h>. */
#include "lx_can.h"

#include <errno.h>
#include <net/if.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/if_arp.h>

#define LX_CAN_MAX_FILTERS 32
#define LX_CAN_BACKOFF_MIN_US 10000   /* first retry after 10 ms */
#define LX_CAN_BACKOFF_MAX_US 1000000 /* retries at most every 1 s */
/* After bus-off the controller needs 128 x 11 recessive bits and the driver's restart-ms
 * (commonly 100 ms) before it sends again: probing earlier only fails. */
#define LX_CAN_BUSOFF_FIRST_US 100000

struct lx_can {
    int fd;                                   /* CAN_RAW socket, -1 while down */
    char ifname[IFNAMSIZ];                    /* interface name */
    struct can_filter filt[LX_CAN_MAX_FILTERS]; /* receive filters */
    size_t nfilt;                             /* how many (0 = all standard data frames) */
    lx_can_health_t h;                        /* health and counters */
    int64_t next_retry_us;                    /* monotonic time of the next recovery attempt */
};

static int64_t mono_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static void bump(uint32_t *v)
{
    if (*v < UINT32_MAX) {
        (*v)++;
    }
}

/* Socket bound to the interface with our filters; -1 and errno on failure. */
static int open_socket(lx_can_t *c, int *ifindex_out)
{
    unsigned idx = if_nametoindex(c->ifname);
    if (idx == 0) {
        errno = ENODEV;
        return -1;
    }
    int fd = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        return -1;
    }
    struct ifreq ifr;
    memset(&ifr, 0, sizeof ifr);
    memcpy(ifr.ifr_name, c->ifname, sizeof ifr.ifr_name);
    if (ioctl(fd, SIOCGIFHWADDR, &ifr) < 0 || ifr.ifr_hwaddr.sa_family != ARPHRD_CAN) {
        close(fd);
        errno = EPROTOTYPE;
        return -1;
    }
    /* Only standard data frames with our ids: EFF and RTR bits are in the mask. */
    struct can_filter all = {0, CAN_EFF_FLAG | CAN_RTR_FLAG};
    const struct can_filter *filt = c->nfilt ? c->filt : &all;
    socklen_t flen = (socklen_t)((c->nfilt ? c->nfilt : 1) * sizeof(struct can_filter));
    can_err_mask_t err_mask = CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_BUSERROR |
                              CAN_ERR_RESTARTED;
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = (int)idx;
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filt, flen) < 0 ||
        setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) < 0 ||
        bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0) {
        int e = errno;
        close(fd);
        errno = e;
        return -1;
    }
    if (ifindex_out) {
        *ifindex_out = (int)idx;
    }
    return fd;
}

/* Interface administratively up? -1 when it does not exist. */
static int iface_up(const char *name)
{
    int s = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (s < 0) {
        return -1;
    }
    struct ifreq ifr;
    memset(&ifr, 0, sizeof ifr);
    memcpy(ifr.ifr_name, name, sizeof ifr.ifr_name);
    int r = ioctl(s, SIOCGIFFLAGS, &ifr);
    close(s);
    if (r < 0) {
        return -1;
    }
    return (ifr.ifr_flags & IFF_UP) ? 1 : 0;
}

static void enter_down(lx_can_t *c, lx_can_link_t why, int err)
{
    int64_t now = mono_us();
    c->h.last_errno = err;
    if (c->h.link == LX_CAN_LINK_OK || c->h.link == LX_CAN_LINK_PASSIVE) {
        c->h.backoff_us = why == LX_CAN_LINK_BUS_OFF ? LX_CAN_BUSOFF_FIRST_US : LX_CAN_BACKOFF_MIN_US;
    } else {
        c->h.backoff_us = c->h.backoff_us * 2 > LX_CAN_BACKOFF_MAX_US ? LX_CAN_BACKOFF_MAX_US : c->h.backoff_us * 2;
    }
    c->h.link = why;
    c->next_retry_us = now + c->h.backoff_us;
}

static void mark_recovered(lx_can_t *c)
{
    if (c->h.link == LX_CAN_LINK_DOWN || c->h.link == LX_CAN_LINK_BUS_OFF) {
        bump(&c->h.recoveries);
    }
    c->h.link = LX_CAN_LINK_OK;
    c->h.backoff_us = 0;
}

/* When a recovery attempt is due: for DOWN, wait for the interface to exist and be up,
 * then re-open and re-bind (an unregistered interface unbinds the old socket). For
 * BUS_OFF, the controller restarts itself (restart-ms); the next send is the probe. */
static void try_recover(lx_can_t *c)
{
    if (c->h.link != LX_CAN_LINK_DOWN && c->h.link != LX_CAN_LINK_BUS_OFF) {
        return;
    }
    if (mono_us() < c->next_retry_us) {
        return;
    }
    if (c->h.link == LX_CAN_LINK_BUS_OFF) {
        /* Allow one probe now; a failure doubles the backoff. */
        c->next_retry_us = mono_us();
        return;
    }
    int up = iface_up(c->ifname);
    if (up != 1) {
        enter_down(c, LX_CAN_LINK_DOWN, up < 0 ? ENODEV : ENETDOWN);
        return;
    }
    int fd = open_socket(c, NULL);
    if (fd < 0) {
        enter_down(c, LX_CAN_LINK_DOWN, errno);
        return;
    }
    if (c->fd >= 0) {
        close(c->fd);
    }
    c->fd = fd;
    mark_recovered(c);
}

lx_can_t *lx_can_open(const char *ifname, const uint32_t *ids, size_t nids, char *err, size_t errlen)
{
    if (ifname == NULL || ifname[0] == '\0' || strlen(ifname) >= IFNAMSIZ) {
        snprintf(err, errlen, "can: '%s': interface name empty or longer than %d characters",
                 ifname ? ifname : "", IFNAMSIZ - 1);
        return NULL;
    }
    if (nids > LX_CAN_MAX_FILTERS) {
        snprintf(err, errlen, "can: %s: %zu receive filters, at most %d", ifname, nids, LX_CAN_MAX_FILTERS);
        return NULL;
    }
    for (size_t i = 0; i < nids; i++) {
        if (ids[i] > RFS_CAN_ID_MAX) {
            snprintf(err, errlen, "can: %s: filter id 0x%X is not an 11-bit id", ifname, (unsigned)ids[i]);
            return NULL;
        }
    }
    lx_can_t *c = calloc(1, sizeof *c);
    if (c == NULL) {
        snprintf(err, errlen, "can: %s: out of memory", ifname);
        return NULL;
    }
    memcpy(c->ifname, ifname, strlen(ifname) + 1);
    for (size_t i = 0; i < nids; i++) {
        c->filt[i].can_id = ids[i];
        c->filt[i].can_mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    c->nfilt = nids;
    c->fd = open_socket(c, NULL);
    if (c->fd < 0) {
        int e = errno;
        const char *why = e == ENODEV ? "no such interface"
                          : e == EPROTOTYPE ? "not a CAN interface"
                          : e == EAFNOSUPPORT || e == EPROTONOSUPPORT ? "this kernel has no CAN_RAW support (modprobe can can-raw)"
                          : strerror(e);
        snprintf(err, errlen, "can: %s: %s", ifname, why);
        free(c);
        return NULL;
    }
    c->h.link = LX_CAN_LINK_OK;
    return c;
}

int lx_can_send(lx_can_t *c, const rfs_can_frame_t *f)
{
    if (f->id > RFS_CAN_ID_MAX || f->dlc > 8) {
        /* Programmer error at the call site; refuse and count rather than send garbage. */
        bump(&c->h.tx_failed);
        c->h.last_errno = EINVAL;
        return -1;
    }
    try_recover(c);
    if ((c->h.link == LX_CAN_LINK_DOWN || c->h.link == LX_CAN_LINK_BUS_OFF) && mono_us() < c->next_retry_us) {
        bump(&c->h.tx_failed);
        return -1;
    }
    if (c->fd < 0) {
        bump(&c->h.tx_failed);
        return -1;
    }
    struct can_frame cf;
    memset(&cf, 0, sizeof cf);
    cf.can_id = f->id;
    cf.len = f->dlc;
    memcpy(cf.data, f->data, f->dlc);
    ssize_t n = write(c->fd, &cf, sizeof cf);
    if (n == (ssize_t)sizeof cf) {
        bump(&c->h.tx_frames);
        mark_recovered(c);
        return 0;
    }
    int e = n < 0 ? errno : EIO;
    bump(&c->h.tx_failed);
    if (e == ENETDOWN || e == ENODEV || e == ENXIO) {
        enter_down(c, LX_CAN_LINK_DOWN, e);
    } else if (c->h.link == LX_CAN_LINK_BUS_OFF) {
        enter_down(c, LX_CAN_LINK_BUS_OFF, e);
    } else {
        /* ENOBUFS/EAGAIN: the queue is full (no ACK on the bus); not a link change. */
        c->h.last_errno = e;
    }
    return -1;
}

static void on_error_frame(lx_can_t *c, const struct can_frame *cf)
{
    bump(&c->h.err_frames);
    canid_t cls = cf->can_id & CAN_ERR_MASK;
    if (cls & CAN_ERR_BUSOFF) {
        bump(&c->h.bus_off);
        enter_down(c, LX_CAN_LINK_BUS_OFF, 0);
        return;
    }
    if (cls & CAN_ERR_RESTARTED) {
        mark_recovered(c);
        return;
    }
    if (cls & CAN_ERR_CRTL) {
        uint8_t d1 = cf->len > 1 ? cf->data[1] : 0;
        if (d1 & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE | CAN_ERR_CRTL_RX_WARNING |
                  CAN_ERR_CRTL_TX_WARNING)) {
            if (c->h.link == LX_CAN_LINK_OK) {
                c->h.link = LX_CAN_LINK_PASSIVE;
            }
        } else if ((d1 & CAN_ERR_CRTL_ACTIVE) && c->h.link == LX_CAN_LINK_PASSIVE) {
            c->h.link = LX_CAN_LINK_OK;
        }
    }
}

int lx_can_recv(lx_can_t *c, rfs_can_frame_t *f, int timeout_ms)
{
    int64_t deadline = mono_us() + (int64_t)(timeout_ms < 0 ? 0 : timeout_ms) * 1000;
    for (;;) {
        try_recover(c);
        int64_t now = mono_us();
        int64_t left_us = deadline - now;
        if (c->h.link == LX_CAN_LINK_DOWN || c->fd < 0) {
            if (left_us <= 0) {
                return -1;
            }
            int64_t nap = c->next_retry_us - now;
            nap = nap > left_us ? left_us : (nap < 1000 ? 1000 : nap);
            struct timespec ts = {(time_t)(nap / 1000000), (long)(nap % 1000000) * 1000};
            nanosleep(&ts, NULL);
            continue;
        }
        struct pollfd p = {c->fd, POLLIN, 0};
        int wait_ms = left_us <= 0 ? 0 : (int)((left_us + 999) / 1000);
        if (c->h.link == LX_CAN_LINK_BUS_OFF && c->next_retry_us - now < (int64_t)wait_ms * 1000) {
            wait_ms = (int)((c->next_retry_us - now + 999) / 1000);
            wait_ms = wait_ms < 0 ? 0 : wait_ms;
        }
        int r = poll(&p, 1, wait_ms);
        if (r < 0 && errno != EINTR) {
            c->h.last_errno = errno;
            return -1;
        }
        if (r > 0) {
            struct can_frame cf;
            ssize_t n = read(c->fd, &cf, sizeof cf);
            if (n < 0) {
                int e = errno;
                if (e == EAGAIN || e == EINTR) {
                    continue;
                }
                /* ENETDOWN when the interface went down, ENODEV when it vanished. */
                enter_down(c, LX_CAN_LINK_DOWN, e);
                continue;
            }
            if (n != (ssize_t)sizeof cf) {
                bump(&c->h.rx_foreign); /* a CAN FD frame or a short read */
                continue;
            }
            if (cf.can_id & CAN_ERR_FLAG) {
                on_error_frame(c, &cf);
                continue;
            }
            if ((cf.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) || cf.len > 8) {
                bump(&c->h.rx_foreign);
                continue;
            }
            f->id = cf.can_id & CAN_SFF_MASK;
            f->dlc = cf.len;
            memset(f->data, 0, sizeof f->data);
            memcpy(f->data, cf.data, cf.len);
            bump(&c->h.rx_frames);
            return 1;
        }
        if (mono_us() >= deadline) {
            return 0;
        }
    }
}

lx_can_link_t lx_can_health(lx_can_t *c, lx_can_health_t *h)
{
    try_recover(c);
    if (h) {
        *h = c->h;
    }
    return c->h.link;
}

void lx_can_close(lx_can_t *c)
{
    if (c == NULL) {
        return;
    }
    if (c->fd >= 0) {
        close(c->fd);
    }
    free(c);
}
