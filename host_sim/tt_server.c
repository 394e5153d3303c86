/* libmodbus slave for the simulated turntable: checks write addresses, replies with
 * modbus_reply on a mapping mirrored from the controller, then lets the controller act. */
#define _POSIX_C_SOURCE 200809L
#include "tt_server.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

static int init_common(struct tt_server *s, tt_now_fn now, void *now_priv, char *err,
                       size_t err_len)
{
    s->now = now;
    s->now_priv = now_priv;
    s->listen_fd = -1;
    pthread_mutex_init(&s->lock, NULL);
    tt_ctrl_init(&s->ctrl, 37500, now(now_priv)); /* powered on somewhere: homing moves it */
    s->mapping = modbus_mapping_new_start_address(0, 0, 0, 0, 0, TT_REG_COUNT, 0, 0);
    if (s->mapping == NULL) {
        snprintf(err, err_len, "turntable-sim: %s", modbus_strerror(errno));
        return -ENOMEM;
    }
    /* A quiet link is normal: wake up now and then to see whether we should stop. */
    modbus_set_indication_timeout(s->ctx, 0, 200000);
    return 0;
}

int tt_server_open_tcp(struct tt_server *s, const char *host, int port, tt_now_fn now,
                       void *now_priv, char *err, size_t err_len)
{
    memset(s, 0, sizeof(*s));
    s->is_tcp = 1;
    s->ctx = modbus_new_tcp(host, port);
    if (s->ctx == NULL) {
        snprintf(err, err_len, "turntable-sim: bad TCP address %s:%d", host, port);
        return -EINVAL;
    }
    int rc = init_common(s, now, now_priv, err, err_len);
    if (rc != 0)
        return rc;
    s->listen_fd = modbus_tcp_listen(s->ctx, 1);
    if (s->listen_fd < 0) {
        rc = -errno;
        snprintf(err, err_len, "turntable-sim: cannot listen on %s:%d: %s", host, port,
                 modbus_strerror(errno));
        tt_server_close(s);
        return rc;
    }
    struct sockaddr_in addr;
    socklen_t len = sizeof(addr);
    getsockname(s->listen_fd, (struct sockaddr *)&addr, &len);
    s->port = ntohs(addr.sin_port);
    return 0;
}

int tt_server_open_rtu(struct tt_server *s, const char *device, int baud, char parity, int unit_id,
                       tt_now_fn now, void *now_priv, char *err, size_t err_len)
{
    memset(s, 0, sizeof(*s));
    s->ctx = modbus_new_rtu(device, baud, parity, 8, 1);
    if (s->ctx == NULL) {
        snprintf(err, err_len, "turntable-sim: bad RTU settings for %s", device);
        return -EINVAL;
    }
    int rc = init_common(s, now, now_priv, err, err_len);
    if (rc != 0)
        return rc;
    modbus_set_slave(s->ctx, unit_id);
    if (modbus_connect(s->ctx) != 0) {
        rc = -errno;
        snprintf(err, err_len, "turntable-sim: cannot open %s: %s", device, modbus_strerror(errno));
        tt_server_close(s);
        return rc;
    }
    return 0;
}

/* Answer one request: refuse writes to read-only registers, otherwise reply from the mapping
 * and let the controller act on what was written. */
static void answer(struct tt_server *s, const uint8_t *req, int len)
{
    modbus_mapping_t *map = s->mapping;
    int off = modbus_get_header_length(s->ctx);
    int function = req[off];
    int addr = (req[off + 1] << 8) | req[off + 2];
    int count = function == 0x06 ? 1 : (req[off + 3] << 8) | req[off + 4];
    pthread_mutex_lock(&s->lock);
    uint64_t now = s->now(s->now_priv);
    tt_ctrl_update(&s->ctrl, now);
    if (s->busy_replies > 0) {
        s->busy_replies--;
        s->requests++;
        pthread_mutex_unlock(&s->lock);
        modbus_reply_exception(s->ctx, req, MODBUS_EXCEPTION_SLAVE_OR_SERVER_BUSY);
        return;
    }
    if ((function == 0x06 || function == 0x10) && tt_ctrl_check_write(&s->ctrl, addr, count)) {
        pthread_mutex_unlock(&s->lock);
        modbus_reply_exception(s->ctx, req, MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS);
        return;
    }
    memcpy(map->tab_registers, s->ctrl.regs, sizeof(s->ctrl.regs));
    int rc = modbus_reply(s->ctx, req, len, map);
    if (rc >= 0 && (function == 0x06 || function == 0x10)) {
        memcpy(s->ctrl.regs, map->tab_registers, sizeof(s->ctrl.regs));
        tt_ctrl_after_write(&s->ctrl, now);
    }
    s->requests++;
    pthread_mutex_unlock(&s->lock);
}

/* TCP: wait for a client (checking the stop flag), then serve it until it leaves. */
static int accept_client(struct tt_server *s)
{
    struct pollfd pfd = {.fd = s->listen_fd, .events = POLLIN};
    while (!s->stop) {
        if (poll(&pfd, 1, 200) > 0)
            return modbus_tcp_accept(s->ctx, &s->listen_fd) >= 0 ? 0 : -1;
    }
    return -1;
}

void tt_server_run(struct tt_server *s)
{
    uint8_t req[MODBUS_TCP_MAX_ADU_LENGTH];
    int connected = !s->is_tcp;
    while (!s->stop) {
        if (!connected) {
            if (accept_client(s) != 0)
                continue;
            connected = 1;
        }
        int len = modbus_receive(s->ctx, req);
        if (len > 0 && s->is_tcp && s->drop_at_request != 0 &&
            s->requests + 1 == s->drop_at_request) {
            s->drop_at_request = 0; /* once: the controller is back for the reconnect */
            if (s->restart_on_drop) {
                pthread_mutex_lock(&s->lock);
                double physical = tt_ctrl_physical_mdeg(&s->ctrl);
                tt_ctrl_init(&s->ctrl, 0, s->now(s->now_priv)); /* reports 0 ... */
                s->ctrl.physical_offset_mdeg = physical;        /* ... where it stands */
                s->ctrl.homed = s->restart_homed;
                pthread_mutex_unlock(&s->lock);
                s->restart_on_drop = 0;
            }
            close(modbus_get_socket(s->ctx));
            modbus_set_socket(s->ctx, -1);
            connected = 0;
        } else if (len > 0) {
            answer(s, req, len);
        } else if (len < 0 && errno != ETIMEDOUT && s->is_tcp) {
            close(modbus_get_socket(s->ctx)); /* the client left: wait for the next one */
            modbus_set_socket(s->ctx, -1);
            connected = 0;
        } else if (len < 0 && errno != ETIMEDOUT) {
            modbus_flush(s->ctx); /* RTU: a garbled frame; drop it */
        }
    }
}

static void *server_thread(void *arg)
{
    tt_server_run(arg);
    return NULL;
}

int tt_server_start(struct tt_server *s)
{
    s->stop = 0;
    int rc = pthread_create(&s->thread, NULL, server_thread, s);
    if (rc != 0)
        return -rc;
    s->running = 1;
    return 0;
}

void tt_server_close(struct tt_server *s)
{
    if (s->running) {
        s->stop = 1;
        pthread_join(s->thread, NULL);
        s->running = 0;
    }
    if (s->ctx != NULL) {
        if (s->is_tcp && modbus_get_socket(s->ctx) >= 0)
            close(modbus_get_socket(s->ctx));
        else
            modbus_close(s->ctx);
        modbus_free(s->ctx);
    }
    if (s->listen_fd >= 0)
        close(s->listen_fd);
    if (s->mapping != NULL)
        modbus_mapping_free(s->mapping);
    s->ctx = NULL;
    s->mapping = NULL;
    s->listen_fd = -1;
    pthread_mutex_destroy(&s->lock);
}

int32_t tt_server_position(struct tt_server *s)
{
    pthread_mutex_lock(&s->lock);
    tt_ctrl_update(&s->ctrl, s->now(s->now_priv));
    int32_t pos = tt_ctrl_position(&s->ctrl);
    pthread_mutex_unlock(&s->lock);
    return pos;
}

int32_t tt_server_physical_position(struct tt_server *s)
{
    pthread_mutex_lock(&s->lock);
    tt_ctrl_update(&s->ctrl, s->now(s->now_priv));
    int32_t pos = (int32_t)lround(tt_ctrl_physical_mdeg(&s->ctrl));
    pthread_mutex_unlock(&s->lock);
    return pos;
}
