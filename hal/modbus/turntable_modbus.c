/* Modbus turntable client: every libmodbus error is translated and logged here, once. */
#define _POSIX_C_SOURCE 200809L
#include "turntable_modbus.h"

#include "tt_regs.h"

#include <errno.h>
#include <modbus.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* @retval 1 when @p e is an exception the controller answered (a matched reply) */
static int is_exception(int e)
{
    return e >= EMBXILFUN && e <= EMBXGTAR;
}

/* Translate a libmodbus failure (errno) into an errno-style code and a sentence. */
static int translate(int e, char *msg, size_t len)
{
    if (e == ETIMEDOUT) {
        snprintf(msg, len, "no reply from the controller");
        return -ETIMEDOUT;
    }
    if (is_exception(e)) {
        snprintf(msg, len, "the controller answered exception %d (%s)", e - MODBUS_ENOBASE,
                 modbus_strerror(e));
        return -EIO;
    }
    if (e == EMBBADCRC || e == EMBBADDATA || e == EMBBADEXC || e == EMBMDATA || e == EMBBADSLAVE ||
        e == EMBUNKEXC) {
        snprintf(msg, len, "bad reply (%s)", modbus_strerror(e));
        return -EIO;
    }
    snprintf(msg, len, "%s", modbus_strerror(e));
    return -e;
}

/* Retry only what a second try can cure: an exception is the controller's final word, except
 * "busy" and "acknowledge" (working on it), which ask to be asked again. */
static int retryable(int e)
{
    return !is_exception(e) || e == EMBXSBUSY || e == EMBXACK;
}

/* Before a retry. On TCP a reply that came late, twice or garbled may still be on its way, and a
 * flush cannot know when it has all gone: the next request would read it as its own answer
 * (libmodbus refuses its transaction id, and so on for the rest of the scan). A new connection
 * leaves it behind. An exception was a matched reply, so nothing is left to drop. */
static void recover(struct tt_client *c, int e)
{
    c->interrupted = 1; /* the controller may have restarted meanwhile: checked before a move */
    if (c->is_tcp && !is_exception(e)) {
        modbus_close(c->ctx);
        if (modbus_connect(c->ctx) != 0)
            c->log(HAL_LOG_WARN, "turntable: reconnect to %s:%u failed: %s", c->cfg.host,
                   (unsigned)c->cfg.port, modbus_strerror(errno));
    } else {
        modbus_flush(c->ctx);
    }
    hal_clock_sleep_us(c->clock, (uint64_t)c->cfg.poll_interval_ms * 1000u);
}

/* Read or write @p n registers from @p addr, with bounded retries. */
static int transfer(struct tt_client *c, const char *what, int write, int addr, int n,
                    uint16_t *regs)
{
    char msg[160];
    int rc = -EIO;
    for (uint32_t attempt = 0; attempt <= c->cfg.retries; attempt++) {
        if (attempt > 0)
            c->retries_used++;
        int got = write ? modbus_write_registers(c->ctx, addr, n, regs)
                        : modbus_read_registers(c->ctx, addr, n, regs);
        if (got == n)
            return 0;
        int e = errno;
        rc = translate(e, msg, sizeof(msg));
        if (!retryable(e))
            break;
        c->log(HAL_LOG_WARN, "turntable: %s: %s, try %u of %u", what, msg, (unsigned)attempt + 1,
               (unsigned)c->cfg.retries + 1);
        recover(c, e);
    }
    c->log(HAL_LOG_ERROR, "turntable: %s failed: %s", what, msg);
    return rc;
}

static int check_unchanged(struct tt_client *c, const char *what);

/* Send a command once: if the reply is lost, LAST_ID tells whether it was executed. A move
 * (@p verify) is sent again only to the controller it was meant for: one that restarted while
 * the link was down counts from where the table stood, and the move would go elsewhere. */
static int send_command(struct tt_client *c, uint16_t cmd, const char *what, int verify)
{
    uint16_t id = c->next_id++;
    if (c->next_id == 0)
        c->next_id = 1;
    uint16_t regs[2] = {cmd, id};
    char msg[160];
    int rc = -EIO;
    for (uint32_t attempt = 0; attempt <= c->cfg.retries; attempt++) {
        if (attempt > 0)
            c->retries_used++;
        if (modbus_write_registers(c->ctx, TT_REG_COMMAND, 2, regs) == 2) {
            c->last_id = id;
            return 0;
        }
        int e = errno;
        rc = translate(e, msg, sizeof(msg));
        if (!retryable(e))
            break;
        recover(c, e);
        uint16_t last;
        if (modbus_read_registers(c->ctx, TT_REG_LAST_ID, 1, &last) == 1 && last == id) {
            c->log(HAL_LOG_WARN, "turntable: %s: reply lost, but the controller executed it", what);
            c->last_id = id;
            return 0;
        }
        if (verify && (rc = check_unchanged(c, what)) != 0)
            return rc; /* said there */
        c->log(HAL_LOG_WARN, "turntable: %s: %s, try %u of %u", what, msg, (unsigned)attempt + 1,
               (unsigned)c->cfg.retries + 1);
    }
    c->log(HAL_LOG_ERROR, "turntable: %s failed: %s", what, msg);
    return rc;
}

/* STATUS, ACTUAL and ALARM into @p st, and LAST_ID (may be NULL), in one request. */
static int read_status(struct tt_client *c, struct hal_turntable_status *st, uint16_t *last_id)
{
    uint16_t r[TT_REG_LAST_ID - TT_REG_ACTUAL_HI + 1];
    int rc =
        transfer(c, "reading the status", 0, TT_REG_ACTUAL_HI, (int)(sizeof(r) / sizeof(r[0])), r);
    if (rc != 0)
        return rc;
    st->position_mdeg = (int32_t)(((uint32_t)r[0] << 16) | r[1]);
    uint16_t status = r[TT_REG_STATUS - TT_REG_ACTUAL_HI];
    st->busy = (status & TT_STATUS_BUSY) != 0;
    st->homed = (status & TT_STATUS_HOMED) != 0;
    st->alarm_code = (status & TT_STATUS_ALARM) ? r[TT_REG_ALARM - TT_REG_ACTUAL_HI] : 0;
    if (last_id != NULL)
        *last_id = r[TT_REG_LAST_ID - TT_REG_ACTUAL_HI];
    return 0;
}

static int tt_get_status(void *priv, struct hal_turntable_status *st)
{
    return read_status(priv, st, NULL);
}

/* Poll until the table is idle; an alarm, the move timeout or (@p moving) a controller that is
 * no longer homed ends the wait with an error. */
static int wait_idle(struct tt_client *c, const char *what, struct hal_turntable_status *st,
                     int moving)
{
    uint64_t start, now;
    hal_clock_now_us(c->clock, &start);
    for (;;) {
        uint16_t last_id;
        int rc = read_status(c, st, &last_id);
        if (rc != 0)
            return rc;
        if (st->alarm_code != 0) {
            c->log(HAL_LOG_ERROR, "turntable: %s: the controller raised alarm %u (%s) at %.3f deg",
                   what, (unsigned)st->alarm_code, tt_alarm_text(st->alarm_code),
                   st->position_mdeg / 1000.0);
            return -EIO;
        }
        if (moving && !st->homed) { /* restarted under the move: its angles are not ours */
            c->log(HAL_LOG_ERROR,
                   "turntable: %s: the controller restarted during the move (no longer homed, "
                   "at %.3f deg by its count); the table must be homed again",
                   what, st->position_mdeg / 1000.0);
            c->lost = 1;
            return -EIO;
        }
        /* Done once the controller has taken this command (LAST_ID) and is idle again: idle
         * before it took it means it has not started, not that it has arrived. */
        if (!st->busy && last_id == c->last_id)
            return 0;
        hal_clock_now_us(c->clock, &now);
        if (now - start > (uint64_t)c->cfg.move_timeout_ms * 1000u) {
            c->log(HAL_LOG_ERROR, "turntable: %s: still moving after %u ms (at %.3f deg); stopped",
                   what, (unsigned)c->cfg.move_timeout_ms, st->position_mdeg / 1000.0);
            send_command(c, TT_CMD_STOP, "stop", 0);
            return -ETIMEDOUT;
        }
        rc = hal_clock_sleep_us(c->clock, (uint64_t)c->cfg.poll_interval_ms * 1000u);
        if (rc != 0)
            return rc;
    }
}

static int tt_home(void *priv)
{
    struct tt_client *c = priv;
    struct hal_turntable_status st;
    int rc = send_command(c, TT_CMD_HOME, "homing", 0);
    if (rc == 0)
        rc = wait_idle(c, "homing", &st, 0);
    if (rc == 0 && !st.homed) {
        c->log(HAL_LOG_ERROR, "turntable: homing ended without the homed flag");
        rc = -EIO;
    }
    c->homed = rc == 0;
    c->lost = 0;
    c->interrupted = 0;
    c->position_known = rc == 0;
    if (rc == 0)
        c->position_mdeg = st.position_mdeg;
    return rc;
}

/* Before a move: is the controller still the one we homed, with the table where we left it? A
 * controller that restarted has forgotten its reference (not homed) or taken its power-on
 * position as zero, and its command counter starts again; a table turned by hand is elsewhere.
 * Moving on would take the next view at another angle than the one recorded. */
static int check_unchanged(struct tt_client *c, const char *what)
{
    struct hal_turntable_status st;
    uint16_t last_id;
    if (c->lost) {
        c->log(HAL_LOG_ERROR, "turntable: %s: refused: the table must be homed again first", what);
        return -EIO;
    }
    int rc = read_status(c, &st, &last_id);
    if (rc != 0 || !c->homed)
        return rc;
    if (!st.homed || last_id != c->last_id) {
        c->log(HAL_LOG_ERROR,
               "turntable: %s: the controller restarted (%s, last command %u where %u was "
               "executed); it was not moved and must be homed again",
               what, st.homed ? "homed" : "no longer homed", (unsigned)last_id,
               (unsigned)c->last_id);
        c->lost = 1;
        return -EIO;
    }
    if (c->position_known &&
        labs((long)st.position_mdeg - (long)c->position_mdeg) > (long)c->cfg.tolerance_mdeg) {
        c->log(HAL_LOG_ERROR,
               "turntable: %s: the table is at %.3f deg, not at %.3f deg where the last move "
               "left it (turned by hand, or the controller re-zeroed); it was not moved and "
               "must be homed again",
               what, st.position_mdeg / 1000.0, c->position_mdeg / 1000.0);
        c->lost = 1;
        return -EIO;
    }
    return 0;
}

static int tt_move_to(void *priv, int32_t angle_mdeg)
{
    struct tt_client *c = priv;
    char what[64];
    struct hal_turntable_status st;
    snprintf(what, sizeof(what), "move to %.3f deg", angle_mdeg / 1000.0);
    uint16_t target[2] = {(uint16_t)((uint32_t)angle_mdeg >> 16),
                          (uint16_t)((uint32_t)angle_mdeg & 0xFFFFu)};
    c->interrupted = 0;
    int rc = check_unchanged(c, what);
    if (rc == 0)
        rc = transfer(c, "writing the target", 1, TT_REG_TARGET_HI, 2, target);
    /* the link went down and came back while the target was written: the same controller? */
    if (rc == 0 && c->interrupted)
        rc = check_unchanged(c, what);
    if (rc == 0)
        rc = send_command(c, TT_CMD_MOVE, what, 1);
    c->position_known = 0; /* until the move ends where it should */
    if (rc == 0)
        rc = wait_idle(c, what, &st, c->homed);
    if (rc != 0)
        return rc;
    long miss = labs((long)st.position_mdeg - (long)angle_mdeg);
    if (miss > (long)c->cfg.tolerance_mdeg) {
        c->log(HAL_LOG_ERROR, "turntable: %s: stopped at %.3f deg", what,
               st.position_mdeg / 1000.0);
        return -EIO;
    }
    c->position_known = 1;
    c->position_mdeg = st.position_mdeg;
    return hal_clock_sleep_us(c->clock, (uint64_t)c->cfg.settle_ms * 1000u);
}

static int tt_safe_state(void *priv)
{
    struct tt_client *c = priv;
    return c->ctx != NULL ? send_command(c, TT_CMD_STOP, "stop", 0) : 0;
}

static int tt_clear_alarm(void *priv)
{
    struct tt_client *c = priv;
    struct hal_turntable_status st;
    int rc = send_command(c, TT_CMD_CLEAR_ALARM, "clearing the alarm", 0);
    if (rc == 0)
        rc = tt_get_status(c, &st);
    if (rc == 0 && st.alarm_code != 0) {
        c->log(HAL_LOG_ERROR, "turntable: alarm %u is still raised after clearing it",
               (unsigned)st.alarm_code);
        rc = -EIO;
    }
    return rc;
}

static const struct hal_turntable_ops tt_ops = {
    .home = tt_home,
    .move_to = tt_move_to,
    .get_status = tt_get_status,
    .safe_state = tt_safe_state,
    .clear_alarm = tt_clear_alarm,
};

static modbus_t *new_context(const struct tt_client_config *cfg)
{
    if (strcmp(cfg->transport, "tcp") == 0)
        return modbus_new_tcp(cfg->host, (int)cfg->port);
    char parity = strcmp(cfg->parity, "even") == 0  ? 'E'
                  : strcmp(cfg->parity, "odd") == 0 ? 'O'
                                                    : 'N';
    return modbus_new_rtu(cfg->device, (int)cfg->baud, parity, 8, 1);
}

int tt_client_open(struct tt_client *c, const struct tt_client_config *cfg,
                   const struct hal_clock *clock,
                   void (*log)(enum hal_log_level level, const char *fmt, ...),
                   struct hal_turntable *out, char *err, size_t err_len)
{
    memset(c, 0, sizeof(*c));
    c->cfg = *cfg;
    c->clock = clock;
    c->log = log;
    c->is_tcp = strcmp(cfg->transport, "tcp") == 0;
    char where[200];
    if (c->is_tcp)
        snprintf(where, sizeof(where), "%s:%u", cfg->host, (unsigned)cfg->port);
    else
        snprintf(where, sizeof(where), "%s", cfg->device);
    modbus_t *ctx = new_context(cfg);
    if (ctx == NULL) {
        snprintf(err, err_len, "turntable: bad Modbus settings for %s", where);
        return -EINVAL;
    }
    c->ctx = ctx;
    modbus_set_slave(ctx, (int)cfg->unit_id);
    modbus_set_error_recovery(ctx, MODBUS_ERROR_RECOVERY_NONE); /* our retries are bounded */
    modbus_set_response_timeout(ctx, cfg->response_timeout_ms / 1000u,
                                (cfg->response_timeout_ms % 1000u) * 1000u);
    modbus_set_byte_timeout(ctx, cfg->byte_timeout_ms / 1000u,
                            (cfg->byte_timeout_ms % 1000u) * 1000u);
    int rc;
    char msg[160];
    if (modbus_connect(ctx) != 0) {
        rc = translate(errno, msg, sizeof(msg));
        snprintf(err, err_len, "turntable: cannot connect to %s: %s", where, msg);
        goto out_free;
    }
    uint16_t ident[TT_REG_COUNT];
    rc = transfer(c, "identifying the controller", 0, 0, TT_REG_COUNT, ident);
    if (rc != 0) {
        snprintf(err, err_len, "turntable: no turntable controller answers at %s (unit %u)", where,
                 (unsigned)cfg->unit_id);
        goto out_close;
    }
    if (ident[TT_REG_DEVICE_ID] != TT_DEVICE_ID) {
        rc = -ENODEV;
        snprintf(err, err_len,
                 "turntable: the device at %s is not a turntable controller "
                 "(DEVICE_ID 0x%04x)",
                 where, (unsigned)ident[TT_REG_DEVICE_ID]);
        goto out_close;
    }
    c->next_id = (uint16_t)(ident[TT_REG_LAST_ID] + 1u);
    if (c->next_id == 0)
        c->next_id = 1;
    uint16_t profile[2] = {(uint16_t)(cfg->speed_dps * 10.0 + 0.5),
                           (uint16_t)(cfg->accel_dps2 * 10.0 + 0.5)};
    rc = transfer(c, "writing the motion profile", 1, TT_REG_SPEED, 2, profile);
    if (rc != 0) {
        snprintf(err, err_len, "turntable: cannot write the motion profile to %s", where);
        goto out_close;
    }
    out->ops = &tt_ops;
    out->priv = c;
    return 0;
out_close:
    modbus_close(ctx);
out_free:
    modbus_free(ctx);
    c->ctx = NULL;
    return rc;
}

void tt_client_close(struct tt_client *c)
{
    if (c->ctx == NULL)
        return;
    modbus_close(c->ctx);
    modbus_free(c->ctx);
    c->ctx = NULL;
}
