/* Fuzz target: the turntable client's handling of Modbus replies. A fake controller on loopback
 * TCP answers each request with the input's next chunk (a length byte, then that many bytes);
 * the client connects, identifies it, reads the status, homes and moves. Whatever comes back
 * (torn frames, wrong ids, exceptions, absurd registers, a dropped connection), the client must
 * return an error or a sane result, never crash or hang past its bounded retries. */
#define _GNU_SOURCE
#include "fuzz_input.h"

#include "hal.h"
#include "sim_devices.h"
#include "turntable_modbus.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <string.h>
#include <sys/socket.h>

static int listen_fd = -1, port;
static const uint8_t *feed;
static size_t feed_left;
static volatile int stop;

static void quiet(enum hal_log_level level, const char *fmt, ...)
{
    (void)level;
    (void)fmt;
}

static void listen_once(void)
{
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    socklen_t len = sizeof(a);
    listen_fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (listen_fd < 0 || bind(listen_fd, (struct sockaddr *)&a, sizeof(a)) != 0 ||
        listen(listen_fd, 8) != 0 || getsockname(listen_fd, (struct sockaddr *)&a, &len) != 0)
        abort();
    port = ntohs(a.sin_port);
}

/* Serve one connection: after each request, the next chunk of the input; then close. */
static void serve(int fd)
{
    uint8_t req[300];
    struct pollfd p = {.fd = fd, .events = POLLIN};
    while (!stop && feed_left > 0 && poll(&p, 1, 50) > 0) {
        if (read(fd, req, sizeof(req)) <= 0)
            break;
        size_t n = feed[0];
        feed++, feed_left--;
        if (n > feed_left)
            n = feed_left;
        if (n > 0 && write(fd, feed, n) < 0)
            break;
        feed += n, feed_left -= n;
    }
    close(fd);
}

static void *controller(void *arg)
{
    (void)arg;
    struct pollfd p = {.fd = listen_fd, .events = POLLIN};
    while (!stop)
        if (poll(&p, 1, 10) > 0) {
            int fd = accept(listen_fd, NULL, NULL);
            if (fd >= 0)
                serve(fd); /* a reconnect after the input ran out is closed at once */
        }
    return NULL;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct clock_sim clock_state;
    static struct hal_clock clock;
    if (listen_fd < 0) {
        listen_once();
        clock_sim_init(&clock_state, &clock); /* virtual: timeouts pass without waiting */
    }
    feed = data;
    feed_left = size;
    stop = 0;
    pthread_t t;
    if (pthread_create(&t, NULL, controller, NULL) != 0)
        abort();
    struct tt_client_config cfg;
    memset(&cfg, 0, sizeof(cfg));
    snprintf(cfg.transport, sizeof(cfg.transport), "tcp");
    snprintf(cfg.host, sizeof(cfg.host), "127.0.0.1");
    cfg.port = (uint32_t)port;
    cfg.unit_id = 1;
    cfg.response_timeout_ms = 20;
    cfg.byte_timeout_ms = 5;
    cfg.retries = 1;
    cfg.poll_interval_ms = 1;
    cfg.move_timeout_ms = 100;
    cfg.speed_dps = 30;
    cfg.accel_dps2 = 60;
    cfg.tolerance_mdeg = 10;
    static struct tt_client client;
    struct hal_turntable table = {NULL, NULL};
    char err[256] = "";
    int rc = tt_client_open(&client, &cfg, &clock, quiet, &table, err, sizeof(err));
    FUZZ_EXPECT(rc <= 0);
    if (rc == 0) {
        struct hal_turntable_status st;
        FUZZ_EXPECT(hal_table_get_status(&table, &st) <= 0);
        FUZZ_EXPECT(hal_table_home(&table) <= 0);
        FUZZ_EXPECT(hal_table_move_to(&table, 90000) <= 0);
        tt_client_close(&client);
    } else {
        FUZZ_EXPECT(strstr(err, "turntable:") != NULL);
    }
    stop = 1;
    pthread_join(t, NULL);
    return 0;
}
