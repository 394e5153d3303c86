/* A null-modem cable in software: two pseudo-terminals whose bytes a thread relays both ways,
 * so an RTU master and slave in one process each open a real serial device path. */
#ifndef PTY_LINK_H
#define PTY_LINK_H

#include <pthread.h>
#include <stddef.h>

struct pty_link {
    int master[2];
    int slave_hold[2]; /* held open so the masters never see EIO while nobody has the slave open */
    char path[2][64];  /* device paths for the two ends */
    pthread_t thread;
    volatile int stop;
    int running;
    /* fault injection (tests): flip one bit of the next byte going from end 1 to end 0 */
    volatile int corrupt_next_reply;
};

/** Create both ends and start relaying. @retval 0 or -errno */
int pty_link_open(struct pty_link *link, char *err, size_t err_len);
void pty_link_close(struct pty_link *link);

#endif
