/* The hostile relay: one client at a time, each with its own upstream connection; every read
 * from upstream is one reply (the client has one request outstanding at a time). */
#define _POSIX_C_SOURCE 200809L
#include "tcp_relay.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

static long long now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static int connect_upstream(int port)
{
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd >= 0 && connect(fd, (struct sockaddr *)&a, sizeof(a)) != 0) {
        close(fd);
        fd = -1;
    }
    return fd;
}

/* A reply from upstream: passed on, held back, or sent twice, as armed. */
struct held {
    unsigned char buf[512];
    ssize_t len;
    long long due_ms; /* 0: nothing held */
};

static void pass_reply(struct tcp_relay *r, int client, const unsigned char *buf, ssize_t n,
                       struct held *h)
{
    pthread_mutex_lock(&r->lock);
    unsigned long k = ++r->replies;
    int delay = r->delay_reply == k, twice = r->duplicate_reply == k;
    unsigned delay_ms = r->delay_ms;
    pthread_mutex_unlock(&r->lock);
    if (delay && (size_t)n <= sizeof(h->buf)) {
        memcpy(h->buf, buf, (size_t)n);
        h->len = n;
        h->due_ms = now_ms() + delay_ms;
        return;
    }
    if (write(client, buf, (size_t)n) < 0)
        return;
    if (twice && write(client, buf, (size_t)n) < 0)
        return;
}

/* Relay one client until either side closes. */
static void serve(struct tcp_relay *r, int client, struct held *h)
{
    int up = connect_upstream(r->upstream_port);
    unsigned char buf[512];
    while (!r->stop && up >= 0) {
        if (h->due_ms != 0 && now_ms() >= h->due_ms) { /* the late reply, at last */
            if (write(client, h->buf, (size_t)h->len) < 0)
                break;
            h->due_ms = 0;
        }
        struct pollfd p[2] = {{.fd = client, .events = POLLIN}, {.fd = up, .events = POLLIN}};
        if (poll(p, 2, 10) <= 0)
            continue;
        if (p[0].revents) {
            ssize_t n = read(client, buf, sizeof(buf));
            if (n <= 0 || write(up, buf, (size_t)n) != n)
                break;
        }
        if (p[1].revents) {
            ssize_t n = read(up, buf, sizeof(buf));
            if (n <= 0)
                break;
            pass_reply(r, client, buf, n, h);
        }
    }
    h->due_ms = 0; /* a reply held for a client that left goes nowhere */
    if (up >= 0)
        close(up);
}

static void *relay_thread(void *arg)
{
    struct tcp_relay *r = arg;
    struct held h = {.due_ms = 0};
    while (!r->stop) {
        struct pollfd p = {.fd = r->listen_fd, .events = POLLIN};
        if (poll(&p, 1, 50) <= 0)
            continue;
        int client = accept(r->listen_fd, NULL, NULL);
        if (client < 0)
            continue;
        pthread_mutex_lock(&r->lock);
        r->connections++;
        pthread_mutex_unlock(&r->lock);
        serve(r, client, &h);
        close(client);
    }
    return NULL;
}

int tcp_relay_start(struct tcp_relay *r, int upstream_port)
{
    memset(r, 0, sizeof(*r));
    r->upstream_port = upstream_port;
    pthread_mutex_init(&r->lock, NULL);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = 0};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof(a);
    r->listen_fd = socket(AF_INET, SOCK_STREAM, 0);
    if (r->listen_fd < 0 || bind(r->listen_fd, (struct sockaddr *)&a, sizeof(a)) != 0 ||
        listen(r->listen_fd, 4) != 0 || getsockname(r->listen_fd, (struct sockaddr *)&a, &len))
        return -errno;
    r->port = ntohs(a.sin_port);
    int rc = pthread_create(&r->thread, NULL, relay_thread, r);
    return -rc;
}

void tcp_relay_delay(struct tcp_relay *r, unsigned long after, unsigned delay_ms)
{
    pthread_mutex_lock(&r->lock);
    r->delay_reply = r->replies + after;
    r->delay_ms = delay_ms;
    pthread_mutex_unlock(&r->lock);
}

void tcp_relay_duplicate(struct tcp_relay *r, unsigned long after)
{
    pthread_mutex_lock(&r->lock);
    r->duplicate_reply = r->replies + after;
    pthread_mutex_unlock(&r->lock);
}

unsigned long tcp_relay_connections(struct tcp_relay *r)
{
    pthread_mutex_lock(&r->lock);
    unsigned long n = r->connections;
    pthread_mutex_unlock(&r->lock);
    return n;
}

void tcp_relay_stop(struct tcp_relay *r)
{
    r->stop = 1;
    pthread_join(r->thread, NULL);
    close(r->listen_fd);
    pthread_mutex_destroy(&r->lock);
}
