/* The simulated controller's Modbus slave on libmodbus's server side: TCP or RTU, one thread. */
#ifndef TT_SERVER_H
#define TT_SERVER_H

#include "tt_ctrl.h"

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

/** Where the controller's time comes from (virtual in process, monotonic standalone). */
typedef uint64_t (*tt_now_fn)(void *priv);

struct tt_server {
    void *ctx;     /* modbus_t *, owned by the server thread once started */
    void *mapping; /* modbus_mapping_t * */
    int listen_fd; /* TCP only */
    int is_tcp;
    int port; /* TCP: the port actually bound */
    struct tt_ctrl ctrl;
    pthread_mutex_t lock; /* guards ctrl: the camera reads the position from another thread */
    tt_now_fn now;
    void *now_priv;
    pthread_t thread;
    int running;
    volatile int stop;
    unsigned long requests; /* requests answered */
    /* fault injection (tests, TCP): after this many requests in all, drop the client without
     * answering, as a pulled cable or a rebooting controller does (0: never) */
    unsigned long drop_at_request;
    /* with drop_at_request: the controller restarts as the link drops (a power glitch): it
     * comes back not homed, counting from where the table stands, its command counter at 0 */
    int restart_on_drop;
    int restart_homed; /* ... and, set, comes back reporting itself homed at 0 (re-zeroed) */
    /* fault injection (tests): answer the next this many requests with exception 6, "server
     * busy", as a controller does while it is occupied */
    unsigned long busy_replies;
};

/** Listen on @p host:@p port (0: any free port, see ->port). @retval 0 or -errno (message in err)
 */
int tt_server_open_tcp(struct tt_server *s, const char *host, int port, tt_now_fn now,
                       void *now_priv, char *err, size_t err_len);
/** Serve RTU on the serial device @p device as slave @p unit_id. @retval 0 or -errno */
int tt_server_open_rtu(struct tt_server *s, const char *device, int baud, char parity, int unit_id,
                       tt_now_fn now, void *now_priv, char *err, size_t err_len);
/** Serve in a thread until tt_server_close. @retval 0 or -errno */
int tt_server_start(struct tt_server *s);
/** Serve requests in the calling thread until ->stop is set (the standalone program). */
void tt_server_run(struct tt_server *s);
void tt_server_close(struct tt_server *s);
/** Position now as reported (advances the motion to now). */
int32_t tt_server_position(struct tt_server *s);
/** Where the table really is now, in millidegrees. */
int32_t tt_server_physical_position(struct tt_server *s);

#endif
