/* Turntable backend: a Modbus master on libmodbus, RTU or TCP, for the register map of
 * docs/turntable-modbus.md. Retries are its own and bounded (libmodbus's link recovery is off). */
#ifndef TURNTABLE_MODBUS_H
#define TURNTABLE_MODBUS_H

#include "hal.h"

#include <stddef.h>
#include <stdint.h>

struct tt_client_config {
    char transport[8]; /**< "tcp" or "rtu" */
    char host[64];
    uint32_t port;
    char device[128];
    uint32_t baud;
    char parity[8]; /**< none | even | odd */
    uint32_t unit_id;
    uint32_t response_timeout_ms; /**< wait for the first byte of a reply */
    uint32_t byte_timeout_ms;     /**< wait between bytes of a reply */
    uint32_t retries;             /**< extra tries of a request that got no (valid) reply */
    uint32_t poll_interval_ms;    /**< status polling while the table moves */
    uint32_t move_timeout_ms;     /**< a move or homing must end within this */
    double speed_dps, accel_dps2; /**< motion profile written at start */
    uint32_t tolerance_mdeg;      /**< reached position must be this close to the target */
    uint32_t settle_ms;           /**< wait after a move before capturing (vibration) */
};

struct tt_client {
    void *ctx; /* modbus_t * */
    struct tt_client_config cfg;
    const struct hal_clock *clock;
    void (*log)(enum hal_log_level level, const char *fmt, ...);
    uint16_t next_id;
    /* What the controller must still say before a move, once homed (a controller that restarts
     * forgets its reference and its command counter; a table turned by hand moves): */
    int homed;             /**< 1 once homed through this client */
    int lost;              /**< 1 once a check failed: no move until homed again */
    uint16_t last_id;      /**< COMMAND_ID of the last command it executed for us */
    int position_known;    /**< 0 after a move that failed: where it stopped is its own */
    int32_t position_mdeg; /**< where the last move (or homing) left it */
    int interrupted;       /**< 1 once a request was retried (the link dropped, a timeout):
                                the controller may have restarted in between */
    int is_tcp;
    unsigned long retries_used; /**< requests repeated since open (for tests and reports) */
};

/** Connect, check that a turntable controller answers, write the motion profile and fill @p out.
 *  @retval 0 ok @retval -ETIMEDOUT no answer @retval -errno, with @p err saying what */
int tt_client_open(struct tt_client *c, const struct tt_client_config *cfg,
                   const struct hal_clock *clock,
                   void (*log)(enum hal_log_level level, const char *fmt, ...),
                   struct hal_turntable *out, char *err, size_t err_len);
void tt_client_close(struct tt_client *c);

#endif
