/* Pseudo-terminal pair relayed by a thread, for Modbus RTU without hardware or socat. */
#define _DEFAULT_SOURCE /* cfmakeraw */
#define _XOPEN_SOURCE 700
#include "pty_link.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

static int open_end(struct pty_link *l, int i)
{
    l->master[i] = posix_openpt(O_RDWR | O_NOCTTY);
    if (l->master[i] < 0 || grantpt(l->master[i]) != 0 || unlockpt(l->master[i]) != 0)
        return -errno;
    const char *name = ptsname(l->master[i]);
    if (name == NULL)
        return -errno;
    snprintf(l->path[i], sizeof(l->path[i]), "%s", name);
    l->slave_hold[i] = open(name, O_RDWR | O_NOCTTY);
    if (l->slave_hold[i] < 0)
        return -errno;
    /* Raw from the start: a cooked line discipline would echo frames back into the relay. */
    struct termios tio;
    tcgetattr(l->slave_hold[i], &tio);
    cfmakeraw(&tio);
    tcsetattr(l->slave_hold[i], TCSANOW, &tio);
    return 0;
}

static void *relay(void *arg)
{
    struct pty_link *l = arg;
    struct pollfd pfd[2] = {{.fd = l->master[0], .events = POLLIN},
                            {.fd = l->master[1], .events = POLLIN}};
    unsigned char buf[512];
    while (!l->stop) {
        if (poll(pfd, 2, 100) <= 0)
            continue;
        for (int i = 0; i < 2; i++) {
            if (!(pfd[i].revents & POLLIN))
                continue;
            ssize_t n = read(l->master[i], buf, sizeof(buf));
            if (n <= 0)
                continue;
            if (i == 1 && l->corrupt_next_reply) {
                buf[n - 1] ^= 0x01; /* the CRC no longer matches */
                l->corrupt_next_reply = 0;
            }
            for (ssize_t off = 0; off < n;) {
                ssize_t w = write(l->master[1 - i], buf + off, (size_t)(n - off));
                if (w <= 0)
                    break;
                off += w;
            }
        }
    }
    return NULL;
}

int pty_link_open(struct pty_link *l, char *err, size_t err_len)
{
    memset(l, 0, sizeof(*l));
    l->master[0] = l->master[1] = l->slave_hold[0] = l->slave_hold[1] = -1;
    int rc = open_end(l, 0);
    if (rc == 0)
        rc = open_end(l, 1);
    if (rc == 0)
        rc = -pthread_create(&l->thread, NULL, relay, l);
    if (rc != 0) {
        snprintf(err, err_len, "pty link: %s", strerror(-rc));
        pty_link_close(l);
        return rc;
    }
    l->running = 1;
    return 0;
}

void pty_link_close(struct pty_link *l)
{
    if (l->running) {
        l->stop = 1;
        pthread_join(l->thread, NULL);
        l->running = 0;
    }
    for (int i = 0; i < 2; i++) {
        if (l->slave_hold[i] >= 0)
            close(l->slave_hold[i]);
        if (l->master[i] >= 0)
            close(l->master[i]);
        l->slave_hold[i] = l->master[i] = -1;
    }
}
