/* Who may ask what of the web server: the Host a request names, the site a browser sends it
 * from, the session key that anything using the rig must carry, the login's rate, and bounds on
 * a JSON body. Checked before a request is served (docs/api.md, "Who may ask"). */
#ifndef GUARD_H
#define GUARD_H

#include <stddef.h>

struct mg_connection;
struct web_server;

#define GUARD_KEY_HEADER "X-Scanner-Key"
#define GUARD_MAX_JSON_DEPTH 32 /* a profile or a token is one level; cJSON recurses per level */

/** Make the session key (random, from getrandom) into @p key (33 bytes: 32 hex digits).
 *  @retval 0 @retval -errno */
int guard_make_key(char *key, size_t len);

/** Check @p listen, civetweb's comma-separated list of ADDR:PORT: 1 when every address is on
 *  loopback (127.x.x.x or [::1]); a bare port or any other address is reachable from the
 *  network. */
int guard_listen_is_loopback(const char *listen);

/** Check a token file's secret: 16 to 255 characters a cookie may carry (no space, ';', ',',
 *  '"' or '\\', nothing outside printable ASCII). @retval NULL fine @retval what is wrong */
const char *guard_token_problem(const char *token);

/** The request's Host and, from a browser, its site: on a server without a token the Host must
 *  name loopback (127.x.x.x, localhost, [::1]; a DNS-rebinding name does not); any request
 *  whose Origin is not this server's, or whose Sec-Fetch-Site is cross-site or same-site, is
 *  refused. @retval 0 may go on @retval 403 (an answer for @p why) */
int guard_request(const struct web_server *s, const struct mg_connection *conn, const char **why);

/** The session key on a request that uses the rig: the header X-Scanner-Key equal to the
 *  server's, which only a page of this server can read (GET /api/session).
 *  @retval 1 it carries it */
int guard_has_key(const struct web_server *s, const struct mg_connection *conn);

/** @retval 1 when secrets @p a and @p b are equal, compared in a time that does not tell how
 *  much of a guess was right */
int guard_secret_equal(const char *a, const char *b);

/** Count a login: @p ok or a wrong token. Wrong tokens are logged with the client's address, and
 *  more than 5 in 10 s make the next attempts wait (a guess a second at most on average).
 *  @retval 0 may try @retval 429 too many wrong tokens just now */
int guard_login_allowed(const struct mg_connection *conn);
void guard_login_failed(const struct mg_connection *conn);

/** Whether @p text (NUL-terminated JSON) nests arrays and objects deeper than @p max levels,
 *  counted without parsing (so that no parser recurses on a hostile body).
 *  @retval 1 deeper @retval 0 not */
int guard_json_too_deep(const char *text, int max);

#endif
