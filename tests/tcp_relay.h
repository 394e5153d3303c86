/* A hostile TCP relay for tests: sits between a Modbus TCP client and its controller on
 * 127.0.0.1 and, when told, holds one reply back past the client's timeout or sends one twice. */
#ifndef TCP_RELAY_H
#define TCP_RELAY_H

#include <pthread.h>

struct tcp_relay {
    int listen_fd;
    int port;          /**< where the client connects */
    int upstream_port; /**< the controller */
    pthread_t thread;
    volatile int stop;
    pthread_mutex_t lock;          /* guards the counters and faults below */
    unsigned long replies;         /**< replies passed on so far */
    unsigned long connections;     /**< client connections accepted so far */
    unsigned long delay_reply;     /**< hold reply number N (counting from 1) back ... */
    unsigned delay_ms;             /**< ... this long, then send it (to whoever is connected) */
    unsigned long duplicate_reply; /**< send reply number N twice */
};

/** Listen on a free port of 127.0.0.1 and relay each client to @p upstream_port.
 *  @retval 0 @retval -errno */
int tcp_relay_start(struct tcp_relay *r, int upstream_port);
/** Arm a fault for the reply after the next @p after replies (1: the very next). */
void tcp_relay_delay(struct tcp_relay *r, unsigned long after, unsigned delay_ms);
void tcp_relay_duplicate(struct tcp_relay *r, unsigned long after);
/** @retval connections accepted so far */
unsigned long tcp_relay_connections(struct tcp_relay *r);
void tcp_relay_stop(struct tcp_relay *r);

#endif
