/* build/turntable-sim: the simulated turntable controller as its own program, on real time,
 * serving Modbus TCP or RTU until SIGINT/SIGTERM. For interoperability tests and for trying
 * a front end against a "turntable" without hardware. */
#define _POSIX_C_SOURCE 200809L
#include "tt_server.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static struct tt_server server;

static uint64_t monotonic_us(void *priv)
{
    (void)priv;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

static void on_signal(int sig)
{
    (void)sig;
    server.stop = 1;
}

static int usage(void)
{
    fprintf(stderr, "usage: turntable-sim --tcp [HOST:]PORT\n"
                    "       turntable-sim --rtu DEVICE [--baud N] [--parity none|even|odd] "
                    "[--unit N]\n"
                    "PORT 0 picks a free port; the port is printed on the first line.\n");
    return 2;
}

int main(int argc, char **argv)
{
    const char *tcp = NULL, *rtu = NULL, *parity = "even";
    int baud = 19200, unit = 1;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--tcp") == 0)
            tcp = argv[i + 1];
        else if (strcmp(argv[i], "--rtu") == 0)
            rtu = argv[i + 1];
        else if (strcmp(argv[i], "--baud") == 0)
            baud = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--parity") == 0)
            parity = argv[i + 1];
        else if (strcmp(argv[i], "--unit") == 0)
            unit = atoi(argv[i + 1]);
        else
            return usage();
    }
    if ((tcp == NULL) == (rtu == NULL) || argc % 2 == 0)
        return usage();
    char err[256], host[64] = "127.0.0.1";
    int rc;
    if (tcp != NULL) {
        const char *colon = strrchr(tcp, ':');
        if (colon != NULL)
            snprintf(host, sizeof(host), "%.*s", (int)(colon - tcp), tcp);
        rc = tt_server_open_tcp(&server, host, atoi(colon ? colon + 1 : tcp), monotonic_us, NULL,
                                err, sizeof(err));
    } else {
        rc = tt_server_open_rtu(&server, rtu, baud, (char)(parity[0] - 32), unit, monotonic_us,
                                NULL, err, sizeof(err));
    }
    if (rc != 0) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    if (tcp != NULL)
        printf("turntable-sim: listening on %s:%d\n", host, server.port);
    else
        printf("turntable-sim: serving unit %d on %s at %d baud\n", unit, rtu, baud);
    fflush(stdout);
    tt_server_run(&server);
    printf("turntable-sim: %lu requests answered\n", server.requests);
    tt_server_close(&server);
    return 0;
}
