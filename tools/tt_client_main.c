/* build/tt-client: the scanner's Modbus turntable client as a command, for interoperability
 * tests against controllers nobody on the team wrote (pymodbus).
 * usage: tt-client tcp HOST PORT | rtu DEVICE BAUD PARITY UNIT, then: status | home | move MDEG */
#define _POSIX_C_SOURCE 200809L
#include "clock_posix.h"
#include "turntable_modbus.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void log_stderr(enum hal_log_level level, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "tt-client: %s: ", level == HAL_LOG_ERROR ? "error" : "note");
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

int main(int argc, char **argv)
{
    struct tt_client_config c;
    memset(&c, 0, sizeof(c));
    int i;
    if (argc >= 4 && strcmp(argv[1], "tcp") == 0) {
        snprintf(c.transport, sizeof(c.transport), "tcp");
        snprintf(c.host, sizeof(c.host), "%s", argv[2]);
        c.port = (uint32_t)atoi(argv[3]);
        c.unit_id = 1;
        i = 4;
    } else if (argc >= 6 && strcmp(argv[1], "rtu") == 0) {
        snprintf(c.transport, sizeof(c.transport), "rtu");
        snprintf(c.device, sizeof(c.device), "%s", argv[2]);
        c.baud = (uint32_t)atoi(argv[3]);
        snprintf(c.parity, sizeof(c.parity), "%s", argv[4]);
        c.unit_id = (uint32_t)atoi(argv[5]);
        i = 6;
    } else {
        fprintf(stderr, "usage: tt-client tcp HOST PORT | rtu DEVICE BAUD PARITY UNIT, "
                        "then status | home | move MDEG ...\n");
        return 2;
    }
    c.response_timeout_ms = 1000;
    c.byte_timeout_ms = 100;
    c.retries = 2;
    c.poll_interval_ms = 20;
    c.move_timeout_ms = 20000;
    c.speed_dps = 180;
    c.accel_dps2 = 720;
    c.tolerance_mdeg = 10;
    struct hal_clock clock;
    struct hal_turntable table;
    struct tt_client client;
    char err[256];
    clock_posix_init(&clock);
    if (tt_client_open(&client, &c, &clock, log_stderr, &table, err, sizeof(err)) != 0) {
        fprintf(stderr, "tt-client: %s\n", err);
        return 1;
    }
    int rc = 0;
    for (; i < argc && rc == 0; i++) {
        if (strcmp(argv[i], "home") == 0) {
            rc = hal_table_home(&table);
        } else if (strcmp(argv[i], "move") == 0 && i + 1 < argc) {
            rc = hal_table_move_to(&table, atoi(argv[++i]));
        } else if (strcmp(argv[i], "status") == 0) {
            struct hal_turntable_status st;
            rc = hal_table_get_status(&table, &st);
            if (rc == 0)
                printf("position_mdeg=%d busy=%d homed=%d alarm=%u\n", (int)st.position_mdeg,
                       st.busy, st.homed, (unsigned)st.alarm_code);
        } else {
            fprintf(stderr, "tt-client: unknown action '%s'\n", argv[i]);
            rc = 2;
        }
    }
    tt_client_close(&client);
    return rc == 0 ? 0 : 1;
}
