/* The person's answer to a question of the scanner (a second pass, a calibration step), read
 * from standard input: typed at a terminal, or written there by scanner serve for the page. */
#ifndef ANSWER_H
#define ANSWER_H

#include "hal.h"

#define ANSWER_MAX_LEN 32 /* bytes of one answer word */

/** Called about every 200 ms while the answer is awaited (a live picture for the page). */
typedef void (*answer_idle_fn)(void *ctx);

/** Wait for a line on standard input naming one of @p answers (an empty line, Enter, is the
 *  first). Polled, so that a stop (a signal) is seen while it waits; a line of anything else is
 *  said (@p hint: what to type) and waited past; over-long lines are cut.
 *  @param idle  called while nothing has come (NULL: none) @param which  out: the index in
 *  @p answers @retval 0 @retval -EINTR a stop was asked for, or the input ended (Ctrl-D) */
int answer_wait(const struct hal *hal, const char *const *answers, unsigned count, const char *hint,
                answer_idle_fn idle, void *ctx, unsigned *which);

#endif
