/* The turntable client against the simulated controller, a real libmodbus slave, over TCP and
 * RTU: every fault the issue lists answered with a bounded, reported error. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <modbus.h>
#include <stdio.h>
#include <string.h>

#include "pty_link.h"
#include "tcp_relay.h"
#include "sim_devices.h"
#include "tt_server.h"
#include "turntable_modbus.h"

static struct clock_sim vclock;
static struct hal_clock vhal_clock;
static struct tt_server server;
static struct pty_link link;
static struct tt_client client;
static struct hal_turntable table;
static char last_log[512];
static int errors_logged;

static void log_capture(enum hal_log_level level, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(last_log, sizeof(last_log), fmt, ap);
    va_end(ap);
    errors_logged += level == HAL_LOG_ERROR;
}

static struct tt_client_config base_config(void)
{
    struct tt_client_config c;
    memset(&c, 0, sizeof(c));
    snprintf(c.transport, sizeof(c.transport), "tcp");
    snprintf(c.host, sizeof(c.host), "127.0.0.1");
    snprintf(c.parity, sizeof(c.parity), "even");
    c.baud = 115200;
    c.unit_id = 1;
    c.response_timeout_ms = 200;
    c.byte_timeout_ms = 50;
    c.retries = 2;
    c.poll_interval_ms = 50;
    c.move_timeout_ms = 30000;
    c.speed_dps = 30;
    c.accel_dps2 = 60;
    c.tolerance_mdeg = 10;
    return c;
}

/* The controller on TCP, the client talking to it directly or through the hostile relay. */
static struct tcp_relay relay;
static int start_tcp(int via_relay)
{
    char err[256];
    errors_logged = 0;
    last_log[0] = '\0';
    clock_sim_init(&vclock, &vhal_clock);
    if (tt_server_open_tcp(&server, "127.0.0.1", 0, clock_sim_now, &vclock, err, sizeof(err)) ||
        tt_server_start(&server) || (via_relay && tcp_relay_start(&relay, server.port)))
        return -1;
    struct tt_client_config c = base_config();
    c.port = (uint32_t)(via_relay ? relay.port : server.port);
    return tt_client_open(&client, &c, &vhal_clock, log_capture, &table, err, sizeof(err));
}

static int open_tcp(void **state)
{
    (void)state;
    return start_tcp(0);
}

static int open_tcp_relay(void **state)
{
    (void)state;
    return start_tcp(1);
}

static int open_rtu(void **state)
{
    (void)state;
    char err[256];
    errors_logged = 0;
    last_log[0] = '\0';
    clock_sim_init(&vclock, &vhal_clock);
    if (pty_link_open(&link, err, sizeof(err)) ||
        tt_server_open_rtu(&server, link.path[1], 115200, 'E', 1, clock_sim_now, &vclock, err,
                           sizeof(err)) ||
        tt_server_start(&server))
        return -1;
    struct tt_client_config c = base_config();
    snprintf(c.transport, sizeof(c.transport), "rtu");
    snprintf(c.device, sizeof(c.device), "%s", link.path[0]);
    return tt_client_open(&client, &c, &vhal_clock, log_capture, &table, err, sizeof(err));
}

static int close_relay(void **state)
{
    tt_client_close(&client);
    tcp_relay_stop(&relay);
    tt_server_close(&server);
    (void)state;
    return 0;
}

/* Five moves there and back, each checked where the controller says the table is. */
static void moves_arrive(void)
{
    for (int k = 1; k <= 5; k++) {
        int32_t to = (k % 2) ? 10000 * k : 0;
        assert_int_equal(hal_table_move_to(&table, to), 0);
        assert_int_equal(tt_server_position(&server), to);
    }
}

/* One reply held back past the timeout, then delivered: before, every later request read the
 * reply of the one before ("Invalid data" to the end of the scan) and the final STOP failed.
 * Now the late reply is left behind with its connection and every later move arrives. */
static void test_late_reply_does_not_desynchronise(void **state)
{
    (void)state;
    assert_int_equal(hal_table_home(&table), 0);
    unsigned long before = tcp_relay_connections(&relay);
    tcp_relay_delay(&relay, 2, 350); /* past the 200 ms response timeout */
    errors_logged = 0;
    moves_arrive();
    assert_int_equal(errors_logged, 0);
    assert_true(tcp_relay_connections(&relay) > before); /* left behind with its connection */
    /* and the STOP of the safe state reaches the controller */
    assert_int_equal(table.ops->safe_state(table.priv), 0);
    pthread_mutex_lock(&server.lock);
    uint16_t last = server.ctrl.last_id, cmd = server.ctrl.regs[TT_REG_COMMAND];
    pthread_mutex_unlock(&server.lock);
    assert_int_equal(last, client.last_id);
    assert_int_equal(cmd, TT_CMD_STOP);
}

/* One reply sent twice: the spare copy answers nobody. */
static void test_duplicated_reply_does_not_desynchronise(void **state)
{
    (void)state;
    assert_int_equal(hal_table_home(&table), 0);
    tcp_relay_duplicate(&relay, 2);
    errors_logged = 0;
    moves_arrive();
    assert_int_equal(errors_logged, 0);
    assert_int_equal(table.ops->safe_state(table.priv), 0);
    pthread_mutex_lock(&server.lock);
    uint16_t last = server.ctrl.last_id;
    pthread_mutex_unlock(&server.lock);
    assert_int_equal(last, client.last_id);
}

static int close_all(void **state)
{
    (void)state;
    tt_client_close(&client);
    tt_server_close(&server);
    if (link.running)
        pty_link_close(&link);
    return 0;
}

/* Home, move, read back: the move takes virtual time as the profile says. */
static void test_home_and_move(void **state)
{
    (void)state;
    struct hal_turntable_status st;
    assert_int_equal(hal_table_get_status(&table, &st), 0);
    assert_int_equal(st.homed, 0);
    assert_int_equal(st.position_mdeg, 37500);
    assert_int_equal(hal_table_home(&table), 0);
    assert_int_equal(hal_table_get_status(&table, &st), 0);
    assert_true(st.homed && !st.busy && st.position_mdeg == 0);
    uint64_t t0 = clock_sim_now(&vclock);
    assert_int_equal(hal_table_move_to(&table, 90000), 0);
    double took_s = (double)(clock_sim_now(&vclock) - t0) / 1e6;
    /* 90 deg at 30 deg/s with 60 deg/s^2: 90/30 + 30/60 = 3.5 s (+ one poll interval) */
    assert_true(took_s >= 3.5 && took_s < 3.5 + 0.2);
    assert_int_equal(hal_table_get_status(&table, &st), 0);
    assert_int_equal(st.position_mdeg, 90000);
    assert_int_equal(hal_table_move_to(&table, -45000), 0);
    assert_int_equal(tt_server_position(&server), -45000);
    assert_int_equal(errors_logged, 0);
}

static void test_move_before_home_raises_alarm(void **state)
{
    (void)state;
    errors_logged = 0;
    assert_int_equal(hal_table_move_to(&table, 10000), -EIO);
    assert_non_null(strstr(last_log, "alarm 2 (move before homing)"));
    assert_int_equal(tt_server_position(&server), 37500); /* it did not move */
    /* the alarm blocks homing too, until cleared */
    modbus_t *raw = client.ctx;
    uint16_t clear[2] = {TT_CMD_CLEAR_ALARM, 999};
    assert_int_equal(modbus_write_registers(raw, TT_REG_COMMAND, 2, clear), 2);
    assert_int_equal(hal_table_home(&table), 0);
}

static void test_stall_reported_with_position(void **state)
{
    (void)state;
    assert_int_equal(hal_table_home(&table), 0);
    pthread_mutex_lock(&server.lock);
    server.ctrl.stall_at_mdeg = 20000;
    pthread_mutex_unlock(&server.lock);
    assert_int_equal(hal_table_move_to(&table, 45000), -EIO);
    assert_non_null(strstr(last_log, "alarm 1 (stall (following error)) at 20.000 deg"));
    pthread_mutex_lock(&server.lock);
    server.ctrl.stall_at_mdeg = INT32_MIN;
    pthread_mutex_unlock(&server.lock);
    /* the alarm blocks motion until the operator clears it */
    assert_int_equal(hal_table_move_to(&table, 45000), -EIO);
    assert_int_equal(hal_table_clear_alarm(&table), 0);
    assert_int_equal(hal_table_move_to(&table, 45000), 0);
    assert_int_equal(tt_server_position(&server), 45000);
}

/* The controller restarts between two views (a brown-out, a watchdog): with @p rezeroed it
 * comes back taking its power-on position as zero and reporting itself homed, no alarm raised;
 * otherwise it comes back not homed. */
static void restart_controller(int rezeroed)
{
    pthread_mutex_lock(&server.lock);
    tt_ctrl_init(&server.ctrl, 0, clock_sim_now(&vclock));
    server.ctrl.homed = rezeroed;
    pthread_mutex_unlock(&server.lock);
}

/* A restarted controller is noticed before the next move, which is not made: the view would be
 * taken at another angle than the one recorded (before: view 2 recorded at 240 deg, taken at 0). */
static void test_restart_noticed_before_the_move(void **state)
{
    (void)state;
    assert_int_equal(hal_table_home(&table), 0);
    assert_int_equal(hal_table_move_to(&table, 180000), 0);
    restart_controller(1);
    errors_logged = 0;
    assert_int_equal(hal_table_move_to(&table, 240000), -EIO);
    assert_int_equal(errors_logged, 1);
    assert_non_null(strstr(last_log, "turntable: move to 240.000 deg: the controller restarted "
                                     "(homed, last command 0 where"));
    assert_int_equal(tt_server_position(&server), 0);          /* it did not move */
    assert_int_equal(hal_table_move_to(&table, 240000), -EIO); /* nor on a second try */
    int rc = hal_table_home(&table);                           /* homing again is the way on */
    if (rc != 0)
        fail_msg("%s", last_log);
    assert_int_equal(hal_table_move_to(&table, 240000), 0);

    restart_controller(0);
    assert_int_equal(hal_table_move_to(&table, 300000), -EIO);
    assert_non_null(strstr(last_log, "the controller restarted (no longer homed"));
    assert_int_equal(tt_server_position(&server), 0);
}

/* The controller restarts (a power glitch) as the link drops, before the move command is
 * executed: the reconnect must not send the move to a controller that counts from where the
 * table stood (before: exit 0, the view recorded at 240 deg while the table stood at 120). */
static void restart_as_the_link_drops(unsigned long at_request, int rezeroed, const char *expect)
{
    assert_int_equal(hal_table_home(&table), 0);
    assert_int_equal(hal_table_move_to(&table, 120000), 0);
    pthread_mutex_lock(&server.lock);
    double physical = tt_ctrl_physical_mdeg(&server.ctrl);
    pthread_mutex_unlock(&server.lock);
    server.restart_on_drop = 1;
    server.restart_homed = rezeroed;
    server.drop_at_request = server.requests + at_request;
    errors_logged = 0;
    assert_int_equal(hal_table_move_to(&table, 240000), -EIO);
    assert_int_equal(server.drop_at_request, 0); /* the drop happened */
    assert_int_equal(errors_logged, 1);
    if (strstr(last_log, expect) == NULL)
        fail_msg("%s", last_log);
    pthread_mutex_lock(&server.lock);
    assert_true(fabs(tt_ctrl_physical_mdeg(&server.ctrl) - physical) < 1.0); /* not moved */
    pthread_mutex_unlock(&server.lock);
    assert_int_equal(hal_table_move_to(&table, 240000), -EIO); /* homing again is the way on */
    assert_int_equal(hal_table_home(&table), 0);
    assert_int_equal(hal_table_move_to(&table, 240000), 0);
}

/* the drop on the move command (request 3: the status check, the target, the command); the
 * controller back not homed, or re-zeroed and saying it is homed (which before went unnoticed) */
static void test_restart_while_sending_the_move(void **state)
{
    (void)state;
    restart_as_the_link_drops(3, 0, "the controller restarted (no longer homed");
    restart_as_the_link_drops(3, 1, "the controller restarted (homed, last command 0 where");
}

/* the drop on the target (request 2): the command is not sent to the restarted controller */
static void test_restart_while_writing_the_target(void **state)
{
    (void)state;
    restart_as_the_link_drops(2, 0, "the controller restarted (no longer homed");
    restart_as_the_link_drops(2, 1, "the controller restarted (homed, last command 0 where");
}

/* the drop while the move is polled (request 5): the restarted controller is not homed, and the
 * wait says so at once (before: polled to the move timeout, then "still moving") */
static void test_restart_during_the_move(void **state)
{
    (void)state;
    assert_int_equal(hal_table_home(&table), 0);
    server.restart_on_drop = 1;
    server.drop_at_request = server.requests + 5;
    errors_logged = 0;
    assert_int_equal(hal_table_move_to(&table, 90000), -EIO);
    assert_int_equal(errors_logged, 1);
    if (strstr(last_log, "the controller restarted during the move (no longer homed") == NULL)
        fail_msg("%s", last_log);
    assert_int_equal(hal_table_move_to(&table, 90000), -EIO); /* until homed again */
}

/* The table turned by hand (or re-zeroed, counter kept) between two views: the same. */
static void test_table_moved_noticed_before_the_move(void **state)
{
    (void)state;
    assert_int_equal(hal_table_home(&table), 0);
    assert_int_equal(hal_table_move_to(&table, 90000), 0);
    pthread_mutex_lock(&server.lock);
    server.ctrl.pos_mdeg = 50000;
    pthread_mutex_unlock(&server.lock);
    errors_logged = 0;
    assert_int_equal(hal_table_move_to(&table, 135000), -EIO);
    assert_int_equal(errors_logged, 1);
    assert_non_null(strstr(last_log, "the table is at 50.000 deg, not at 90.000 deg where the "
                                     "last move left it"));
    assert_int_equal(tt_server_position(&server), 50000);
}

/* "Server busy" (exception 6) asks to be asked again: retried within the same bounds (before,
 * one busy reply stopped the scan); a controller that stays busy is one error. */
static void test_busy_controller_asked_again(void **state)
{
    (void)state;
    assert_int_equal(hal_table_home(&table), 0);
    pthread_mutex_lock(&server.lock);
    server.busy_replies = 2; /* within retries = 2 */
    pthread_mutex_unlock(&server.lock);
    errors_logged = 0;
    assert_int_equal(hal_table_move_to(&table, 30000), 0);
    assert_int_equal(errors_logged, 0);
    assert_int_equal(tt_server_position(&server), 30000);
    pthread_mutex_lock(&server.lock);
    server.busy_replies = 1000;
    pthread_mutex_unlock(&server.lock);
    assert_int_equal(hal_table_move_to(&table, 60000), -EIO);
    assert_int_equal(errors_logged, 1);
    assert_non_null(strstr(last_log, "exception 6"));
    pthread_mutex_lock(&server.lock);
    server.busy_replies = 0;
    pthread_mutex_unlock(&server.lock);
}

/* A controller that takes a while to act on a command reports idle meanwhile: the move is over
 * only once it has taken this command (LAST_ID) and is idle again (before: "did not reach"). */
static void test_slow_controller_move_waits_for_its_command(void **state)
{
    (void)state;
    assert_int_equal(hal_table_home(&table), 0);
    pthread_mutex_lock(&server.lock);
    server.ctrl.command_delay_us = 300000; /* six polls */
    pthread_mutex_unlock(&server.lock);
    errors_logged = 0;
    assert_int_equal(hal_table_move_to(&table, 120000), 0);
    assert_int_equal(errors_logged, 0);
    assert_int_equal(tt_server_position(&server), 120000);
    assert_int_equal(hal_table_move_to(&table, 0), 0);
    assert_int_equal(tt_server_position(&server), 0);
}

/* A read-only register written: the controller's exception, reported as such, not retried. */
static void test_illegal_address_exception(void **state)
{
    (void)state;
    modbus_t *raw = client.ctx;
    uint16_t v = 1;
    assert_int_equal(modbus_write_registers(raw, TT_REG_ACTUAL_HI, 1, &v), -1);
    assert_int_equal(errno, EMBXILADD);
    uint16_t regs[20];
    assert_int_equal(modbus_read_registers(raw, 0, 20, regs), -1); /* past the map */
    assert_int_equal(errno, EMBXILADD);
}

/* The same COMMAND_ID again is a repeat: the controller does not move twice. */
static void test_command_applied_once(void **state)
{
    (void)state;
    assert_int_equal(hal_table_home(&table), 0);
    modbus_t *raw = client.ctx;
    uint16_t target[2] = {0, 10000};
    uint16_t cmd[2] = {TT_CMD_MOVE, 4242};
    assert_int_equal(modbus_write_registers(raw, TT_REG_TARGET_HI, 2, target), 2);
    assert_int_equal(modbus_write_registers(raw, TT_REG_COMMAND, 2, cmd), 2);
    hal_clock_sleep_us(&vhal_clock, 5000000);
    assert_int_equal(tt_server_position(&server), 10000);
    target[1] = 30000; /* new target, but the command is a repeat */
    assert_int_equal(modbus_write_registers(raw, TT_REG_TARGET_HI, 2, target), 2);
    assert_int_equal(modbus_write_registers(raw, TT_REG_COMMAND, 2, cmd), 2);
    hal_clock_sleep_us(&vhal_clock, 5000000);
    assert_int_equal(tt_server_position(&server), 10000);
    uint16_t last;
    assert_int_equal(modbus_read_registers(raw, TT_REG_LAST_ID, 1, &last), 1);
    assert_int_equal(last, 4242);
}

/* The controller goes silent: bounded retries, then a timeout that says so. */
static void test_no_reply_times_out(void **state)
{
    (void)state;
    struct hal_turntable_status st;
    server.stop = 1;
    pthread_join(server.thread, NULL); /* the slave stops answering */
    server.running = 0;
    errors_logged = 0;
    unsigned long before = client.retries_used;
    int rc = hal_table_get_status(&table, &st);
    assert_true(rc == -ETIMEDOUT || rc == -ECONNRESET || rc == -EPIPE || rc < 0);
    assert_int_equal(client.retries_used - before, client.cfg.retries);
    assert_int_equal(errors_logged, 1);
    assert_non_null(strstr(last_log, "turntable: reading the status failed"));
}

/* TCP: the connection drops in the middle of a move (cable pulled, controller rebooted) and
 * comes back: the client reconnects within its retries and the move ends where it should. */
static void test_connection_drop_reconnects(void **state)
{
    (void)state;
    struct hal_turntable_status st;
    assert_int_equal(hal_table_home(&table), 0);
    unsigned long before = client.retries_used;
    server.drop_at_request = server.requests + 3; /* while polling the move */
    errors_logged = 0;
    assert_int_equal(hal_table_move_to(&table, 90000), 0);
    assert_int_equal(server.drop_at_request, 0); /* the drop happened */
    assert_true(client.retries_used - before >= 1);
    assert_int_equal(errors_logged, 0);
    assert_int_equal(hal_table_get_status(&table, &st), 0);
    assert_int_equal(st.position_mdeg, 90000);
    assert_int_equal(tt_server_position(&server), 90000);
}

/* RTU: a reply with a bad CRC is dropped, flushed and asked again. */
static void test_rtu_bad_crc_retried(void **state)
{
    (void)state;
    struct hal_turntable_status st;
    unsigned long before = client.retries_used;
    link.corrupt_next_reply = 1;
    errors_logged = 0;
    assert_int_equal(hal_table_get_status(&table, &st), 0);
    assert_int_equal(client.retries_used - before, 1);
    assert_int_equal(errors_logged, 0);
    assert_int_equal(hal_table_home(&table), 0);
    assert_int_equal(hal_table_move_to(&table, 180000), 0);
    assert_int_equal(tt_server_position(&server), 180000);
}

/* RTU: nobody answers for another unit id. */
static void test_rtu_wrong_unit_is_silent(void **state)
{
    (void)state;
    struct tt_client other;
    struct hal_turntable other_table;
    struct tt_client_config c = base_config();
    char err[256];
    snprintf(c.transport, sizeof(c.transport), "rtu");
    snprintf(c.device, sizeof(c.device), "%s", link.path[0]);
    c.unit_id = 7;
    c.retries = 1;
    tt_client_close(&client); /* one master on the line at a time */
    int rc = tt_client_open(&other, &c, &vhal_clock, log_capture, &other_table, err, sizeof(err));
    assert_int_equal(rc, -ETIMEDOUT);
    assert_non_null(strstr(err, "no turntable controller answers at"));
    assert_non_null(strstr(err, "(unit 7)"));
}

/* Connecting where nothing listens: a clear error naming the address. */
static void test_connection_refused(void **state)
{
    (void)state;
    struct tt_client c0;
    struct hal_turntable t0 = {NULL, NULL};
    struct tt_client_config c = base_config();
    char err[256];
    c.port = 1; /* privileged, nothing listens there */
    assert_int_not_equal(tt_client_open(&c0, &c, &vhal_clock, log_capture, &t0, err, sizeof(err)),
                         0);
    assert_non_null(strstr(err, "cannot connect to 127.0.0.1:1"));
    assert_null(t0.ops);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_home_and_move, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_move_before_home_raises_alarm, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_stall_reported_with_position, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_restart_noticed_before_the_move, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_restart_while_sending_the_move, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_restart_while_writing_the_target, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_restart_during_the_move, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_table_moved_noticed_before_the_move, open_tcp,
                                        close_all),
        cmocka_unit_test_setup_teardown(test_busy_controller_asked_again, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_slow_controller_move_waits_for_its_command, open_tcp,
                                        close_all),
        cmocka_unit_test_setup_teardown(test_late_reply_does_not_desynchronise, open_tcp_relay,
                                        close_relay),
        cmocka_unit_test_setup_teardown(test_duplicated_reply_does_not_desynchronise,
                                        open_tcp_relay, close_relay),
        cmocka_unit_test_setup_teardown(test_illegal_address_exception, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_command_applied_once, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_no_reply_times_out, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_connection_drop_reconnects, open_tcp, close_all),
        cmocka_unit_test_setup_teardown(test_home_and_move, open_rtu, close_all),
        cmocka_unit_test_setup_teardown(test_rtu_bad_crc_retried, open_rtu, close_all),
        cmocka_unit_test_setup_teardown(test_rtu_wrong_unit_is_silent, open_rtu, close_all),
        cmocka_unit_test(test_connection_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
