/* The person's answer on standard input (answer.h). */
#define _POSIX_C_SOURCE 200809L
#include "answer.h"

#include <errno.h>
#include <poll.h>
#include <string.h>
#include <unistd.h>

/* @retval the index of @p line among @p answers (an empty line: 0) @retval -1 none */
static int answer_index(const char *line, const char *const *answers, unsigned count)
{
    if (line[0] == '\0')
        return 0;
    for (unsigned k = 0; k < count; k++)
        if (strcmp(line, answers[k]) == 0)
            return (int)k;
    return -1;
}

int answer_wait(const struct hal *hal, const char *const *answers, unsigned count, const char *hint,
                answer_idle_fn idle, void *ctx, unsigned *which)
{
    char line[ANSWER_MAX_LEN + 1];
    size_t len = 0;
    for (;;) {
        if (hal_should_stop(hal))
            return -EINTR;
        struct pollfd pfd = {.fd = STDIN_FILENO, .events = POLLIN};
        int ready = poll(&pfd, 1, 200);
        if (ready < 0 && errno != EINTR)
            return -EINTR;
        if (ready <= 0) {
            if (idle != NULL)
                idle(ctx);
            continue;
        }
        char c;
        ssize_t got = read(STDIN_FILENO, &c, 1);
        if (got < 0 && (errno == EINTR || errno == EAGAIN))
            continue;
        if (got <= 0)
            return -EINTR; /* the input ended: no one will answer */
        if (c == '\r')
            continue;
        if (c != '\n') {
            if (len < ANSWER_MAX_LEN)
                line[len++] = c;
            continue;
        }
        line[len] = '\0';
        len = 0;
        int k = answer_index(line, answers, count);
        if (k >= 0) {
            *which = (unsigned)k;
            return 0;
        }
        hal->log(HAL_LOG_WARN, "answer '%s' not understood: %s", line, hint);
    }
}
