/* The web server's admission checks (guard.h): Host, Origin and Sec-Fetch-Site, the session key,
 * the login's rate and a JSON body's depth. OctoPrint and Jupyter do the same on loopback: a page
 * of another site in the same browser is the attacker, and loopback is no trust boundary. */
#define _GNU_SOURCE
#include "guard.h"

#include "web.h"

#include <arpa/inet.h>
#include <civetweb.h>
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>

int guard_make_key(char *key, size_t len)
{
    unsigned char raw[16];
    if (len < 2 * sizeof(raw) + 1)
        return -ENOSPC;
    if (getrandom(raw, sizeof(raw), 0) != (ssize_t)sizeof(raw))
        return -errno;
    for (size_t i = 0; i < sizeof(raw); i++)
        snprintf(key + 2 * i, 3, "%02x", raw[i]);
    return 0;
}

/* One of civetweb's listening addresses: "127.0.0.1:8080", "[::1]:8080" (a suffix s, r or o
 * after the port changes nothing of where it listens). */
static int one_is_loopback(const char *addr, size_t len)
{
    char a[64], host[48];
    unsigned port;
    int end = 0;
    if (len == 0 || len >= sizeof(a))
        return 0;
    memcpy(a, addr, len);
    a[len] = '\0';
    struct in_addr v4;
    struct in6_addr v6;
    if (sscanf(a, "%47[0-9.]:%u%n", host, &port, &end) == 2 && inet_pton(AF_INET, host, &v4) == 1)
        return (ntohl(v4.s_addr) >> 24) == 127;
    if (sscanf(a, "[%47[0-9a-fA-F:.]]:%u%n", host, &port, &end) == 2 &&
        inet_pton(AF_INET6, host, &v6) == 1)
        return IN6_IS_ADDR_LOOPBACK(&v6);
    return 0; /* a bare port (every interface), a name, anything else */
}

int guard_listen_is_loopback(const char *listen)
{
    for (const char *p = listen;; p++) {
        size_t len = strcspn(p, ",");
        if (!one_is_loopback(p, len))
            return 0;
        p += len;
        if (*p == '\0')
            return 1;
    }
}

const char *guard_token_problem(const char *token)
{
    size_t n = strlen(token);
    if (n < 16)
        return "the token must be 16 characters or more";
    if (n > 255)
        return "the token must be 255 characters or fewer";
    for (const char *c = token; *c != '\0'; c++)
        if (*c <= ' ' || *c > '~' || strchr(";,\"\\", *c) != NULL)
            return "the token may hold printable ASCII only, without space, ';', ',', '\"' or "
                   "'\\\\' (it travels in a cookie)";
    return NULL;
}

/* Host without its port names loopback: localhost, 127.x.x.x or [::1]. */
static int host_is_loopback(const char *host)
{
    char name[256], addr[64];
    struct in_addr v4;
    struct in6_addr v6;
    size_t len = host[0] == '[' ? strcspn(host, "]") + 1 : strcspn(host, ":");
    if (len >= sizeof(name) || (host[len] != '\0' && host[len] != ':'))
        return 0;
    memcpy(name, host, len);
    name[len] = '\0';
    if (strcasecmp(name, "localhost") == 0)
        return 1;
    if (inet_pton(AF_INET, name, &v4) == 1)
        return (ntohl(v4.s_addr) >> 24) == 127;
    if (name[0] == '[' && len >= 3 && len - 2 < sizeof(addr)) {
        memcpy(addr, name + 1, len - 2);
        addr[len - 2] = '\0';
        return inet_pton(AF_INET6, addr, &v6) == 1 && IN6_IS_ADDR_LOOPBACK(&v6);
    }
    return 0;
}

/* Origin is this server: http:// or https:// and the Host the request names. */
static int origin_is_host(const char *origin, const char *host)
{
    const char *rest = strncmp(origin, "http://", 7) == 0    ? origin + 7
                       : strncmp(origin, "https://", 8) == 0 ? origin + 8
                                                             : NULL;
    return rest != NULL && host != NULL && strcasecmp(rest, host) == 0;
}

int guard_request(const struct web_server *s, const struct mg_connection *conn, const char **why)
{
    const char *host = mg_get_header(conn, "Host");
    const char *origin = mg_get_header(conn, "Origin");
    const char *site = mg_get_header(conn, "Sec-Fetch-Site");
    if (s->token[0] == '\0' && host != NULL && !host_is_loopback(host)) {
        *why = "this scanner answers to its loopback names only (Host is not 127.0.0.1, "
               "localhost or [::1])";
        return 403;
    }
    if (origin != NULL && !origin_is_host(origin, host)) {
        *why = "a page of another site may not use this scanner";
        return 403;
    }
    if (site != NULL && strcmp(site, "same-origin") != 0 && strcmp(site, "none") != 0) {
        *why = "a page of another site may not use this scanner";
        return 403;
    }
    return 0;
}

/* Equal without telling by its timing how much of a guess was right. */
static int equal_in_constant_time(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    unsigned diff = (unsigned)(la ^ lb);
    for (size_t i = 0; i < lb; i++)
        diff |= (unsigned)(unsigned char)(i < la ? a[i] : 0) ^ (unsigned char)b[i];
    return diff == 0;
}

int guard_has_key(const struct web_server *s, const struct mg_connection *conn)
{
    const char *key = mg_get_header(conn, GUARD_KEY_HEADER);
    return key != NULL && equal_in_constant_time(key, s->key);
}

int guard_secret_equal(const char *a, const char *b)
{
    return equal_in_constant_time(a, b);
}

/* The last wrong tokens' times: more than LOGIN_BURST within LOGIN_WINDOW_S and the login
 * waits until the oldest is that old. */
#define LOGIN_BURST 5
#define LOGIN_WINDOW_S 10.0
static pthread_mutex_t login_lock = PTHREAD_MUTEX_INITIALIZER;
static double login_failed_at[LOGIN_BURST];
static unsigned login_next, login_refused;

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec / 1e9;
}

int guard_login_allowed(const struct mg_connection *conn)
{
    pthread_mutex_lock(&login_lock);
    double oldest = login_failed_at[login_next]; /* the ring's oldest entry (0: none yet) */
    int allowed = oldest == 0.0 || now_s() - oldest >= LOGIN_WINDOW_S;
    if (!allowed && login_refused++ == 0)
        fprintf(stderr, "scanner-web: too many wrong tokens (the last from %s): logins wait\n",
                mg_get_request_info(conn)->remote_addr);
    if (allowed)
        login_refused = 0;
    pthread_mutex_unlock(&login_lock);
    return allowed ? 0 : 429;
}

void guard_login_failed(const struct mg_connection *conn)
{
    pthread_mutex_lock(&login_lock);
    login_failed_at[login_next] = now_s();
    login_next = (login_next + 1) % LOGIN_BURST;
    pthread_mutex_unlock(&login_lock);
    fprintf(stderr, "scanner-web: a wrong token from %s\n", mg_get_request_info(conn)->remote_addr);
}

int guard_json_too_deep(const char *text, int max)
{
    int depth = 0, in_string = 0;
    for (const char *c = text; *c != '\0'; c++) {
        if (in_string) {
            if (*c == '\\' && c[1] != '\0')
                c++;
            else if (*c == '"')
                in_string = 0;
        } else if (*c == '"') {
            in_string = 1;
        } else if (*c == '[' || *c == '{') {
            if (++depth > max)
                return 1;
        } else if (*c == ']' || *c == '}') {
            depth--;
        }
    }
    return 0;
}
