/* scanner-web (`scanner serve`): the appliance's web page and HTTP API on civetweb. Scans run as
 * `scanner` child processes, so the rig's safety stays where it is (the scanner's one shutdown
 * path); this program never touches a device. */
#define _GNU_SOURCE
#include "api.h"
#include "config.h"
#include "file_posix.h"
#include "guard.h"
#include "web.h"

#include <civetweb.h>
#include <errno.h>
#include <libgen.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef WEB_WWW_DIR
#define WEB_WWW_DIR "/usr/local/share/scanner/www"
#endif

static const char usage_text[] =
    "usage: scanner serve --config FILE [--config FILE2 ...] [--listen ADDR:PORT]\n"
    "                     [--token-file FILE] [--scans DIR] [--calibrations DIR]\n"
    "                     [--www DIR]\n"
    "  --config      a config the page can scan with (a profile: its file name without .ini);\n"
    "                the first is the default and the rig's selftest and snapshot use it\n"
    "  --listen      where to listen (default 127.0.0.1:8080; a comma-separated list\n"
    "                too); any address but loopback needs --token-file\n"
    "  --token-file  a file holding the secret every API request must carry off loopback\n"
    "                (16 to 255 printable characters, no space , ; \" or \\; set at install:\n"
    "                there is no default)\n"
    "  --scans       where scan folders are made and listed (default: the first config's\n"
    "                [output] dir)\n"
    "  --calibrations  where calibrations started from the page keep their captures and\n"
    "                result (default: calibrations beside the scans' folder)\n"
    "  --www         the page's files (default " WEB_WWW_DIR ")\n";

/* The secret: the file's first line, without its line end, whole (a longer one is refused, not
 * cut: the real token would never match) and fit for a cookie. @retval 0 @retval -1 (said) */
static int read_token(const char *path, char *token, size_t len)
{
    char line[1024];
    FILE *f = file_open_regular(path, "r");
    const char *problem = NULL;
    if (f == NULL || fgets(line, sizeof(line), f) == NULL) {
        problem = f == NULL ? file_strerror(errno) : "empty";
    } else {
        line[strcspn(line, "\r\n")] = '\0';
        problem = guard_token_problem(line);
    }
    if (f != NULL)
        fclose(f);
    if (problem == NULL && strlen(line) >= len)
        problem = "the token is too long";
    if (problem != NULL) {
        fprintf(stderr, "scanner serve: --token-file %s: %s\n", path, problem);
        return -1;
    }
    memcpy(token, line, strlen(line) + 1); /* fits: checked above */
    return 0;
}

static int add_profile(struct web_server *s, const char *path)
{
    if (s->profiles == WEB_MAX_PROFILES) {
        fprintf(stderr, "scanner serve: at most %u configs\n", WEB_MAX_PROFILES);
        return -1;
    }
    struct web_profile *p = &s->profile[s->profiles];
    if (realpath(path, p->path) == NULL) {
        fprintf(stderr, "scanner serve: --config %s: %s\n", path, strerror(errno));
        return -1;
    }
    char copy[WEB_PATH];
    snprintf(copy, sizeof(copy), "%s", path);
    snprintf(p->name, sizeof(p->name), "%s", basename(copy));
    char *dot = strrchr(p->name, '.');
    if (dot != NULL && strcmp(dot, ".ini") == 0)
        *dot = '\0';
    for (unsigned i = 0; i < s->profiles; i++)
        if (strcmp(s->profile[i].name, p->name) == 0) {
            fprintf(stderr, "scanner serve: two configs named %s\n", p->name);
            return -1;
        }
    s->profiles++;
    return 0;
}

/* mkdir -p: @retval 0 @retval -1 with errno */
static int make_dirs(const char *path)
{
    char p[WEB_PATH];
    snprintf(p, sizeof(p), "%s", path);
    for (char *slash = strchr(p + 1, '/');; slash = strchr(slash + 1, '/')) {
        if (slash != NULL)
            *slash = '\0';
        if (mkdir(p, 0755) != 0 && errno != EEXIST)
            return -1;
        if (slash == NULL)
            return 0;
        *slash = '/';
    }
}

/* Every config must load (file, line and key said now, not at the first scan). The first's
 * [output] dir holds the scans unless --scans says otherwise. */
static int check_configs(struct web_server *s, const char *scans, const char *calibrations)
{
    struct app_config cfg;
    char err[1024], first_output[WEB_PATH] = "";
    for (unsigned i = 0; i < s->profiles; i++) {
        if (config_load(&cfg, s->profile[i].path, err, sizeof(err)) != 0) {
            fprintf(stderr, "scanner serve: %s\n", err);
            return -1;
        }
        if (i == 0)
            snprintf(first_output, sizeof(first_output), "%s", cfg.output_dir);
    }
    if (scans == NULL)
        scans = first_output;
    if (make_dirs(scans) != 0) {
        fprintf(stderr, "scanner serve: cannot make %s: %s\n", scans, strerror(errno));
        return -1;
    }
    if (realpath(scans, s->scans) == NULL) {
        fprintf(stderr, "scanner serve: %s: %s\n", scans, strerror(errno));
        return -1;
    }
    /* beside the scans, never among them: a calibration's captures are no scan */
    char beside[WEB_PATH + 16];
    if (calibrations == NULL) {
        snprintf(beside, sizeof(beside), "%s/../calibrations", s->scans);
        calibrations = beside;
    }
    if (make_dirs(calibrations) != 0 || realpath(calibrations, s->calibrations) == NULL) {
        fprintf(stderr, "scanner serve: cannot make %s: %s\n", calibrations, strerror(errno));
        return -1;
    }
    return 0;
}

/* The scanner program beside this one; the page where the build put it (a build tree), else
 * where make install puts it beside the programs (PREFIX/share/scanner/www). */
static int find_scanner(struct web_server *s, int www_given)
{
    char self[WEB_PATH], index[WEB_PATH + 16];
    ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
    if (n <= 0)
        return -1;
    self[n] = '\0';
    const char *bin = dirname(self);
    snprintf(index, sizeof(index), "%s/index.html", s->www);
    if (!www_given && access(index, R_OK) != 0)
        snprintf(s->www, sizeof(s->www), "%s/../share/scanner/www", bin);
    snprintf(s->scanner, sizeof(s->scanner), "%s/scanner", bin);
    if (access(s->scanner, X_OK) != 0) {
        fprintf(stderr, "scanner serve: %s: %s\n", s->scanner, strerror(errno));
        return -1;
    }
    return 0;
}

static int log_message(const struct mg_connection *conn, const char *message)
{
    (void)conn;
    fprintf(stderr, "scanner-web: %s\n", message);
    return 1;
}

int main(int argc, char **argv)
{
    static struct web_server s = {.job = {.lock = PTHREAD_MUTEX_INITIALIZER,
                                          .changed = PTHREAD_COND_INITIALIZER,
                                          .fd_in = -1}};
    const char *listen = "127.0.0.1:8080", *token_file = NULL, *scans = NULL;
    const char *calibrations = NULL;
    int www_given = 0;
    snprintf(s.www, sizeof(s.www), "%s", WEB_WWW_DIR);
    int first = argc > 1 && strcmp(argv[1], "serve") == 0 ? 2 : 1;
    for (int i = first; i < argc; i++) {
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            fputs(usage_text, stdout);
            return 0;
        } else if (value != NULL && strcmp(argv[i], "--config") == 0) {
            if (add_profile(&s, value) != 0)
                return 2;
        } else if (value != NULL && strcmp(argv[i], "--listen") == 0) {
            listen = value;
        } else if (value != NULL && strcmp(argv[i], "--token-file") == 0) {
            token_file = value;
        } else if (value != NULL && strcmp(argv[i], "--scans") == 0) {
            scans = value;
        } else if (value != NULL && strcmp(argv[i], "--calibrations") == 0) {
            calibrations = value;
        } else if (value != NULL && strcmp(argv[i], "--www") == 0) {
            snprintf(s.www, sizeof(s.www), "%s", value);
            www_given = 1;
        } else {
            fprintf(stderr, "scanner serve: %s '%s'\n%s",
                    value == NULL && argv[i][0] == '-' && argv[i][1] == '-'
                        ? "a value is missing after"
                        : "unknown argument",
                    argv[i], usage_text);
            return 2;
        }
        i++;
    }
    if (s.profiles == 0) {
        fprintf(stderr, "scanner serve: --config FILE is required\n%s", usage_text);
        return 2;
    }
    if (!guard_listen_is_loopback(listen) && token_file == NULL) {
        fprintf(stderr,
                "scanner serve: --listen %s is reachable from the network: give --token-file "
                "FILE (a secret of 16 to 255 characters, set at install)\n",
                listen);
        return 2;
    }
    if (token_file != NULL && read_token(token_file, s.token, sizeof(s.token)) != 0)
        return 2;
    if (guard_make_key(s.key, sizeof(s.key)) != 0) {
        fprintf(stderr, "scanner serve: no random numbers for the session key: %s\n",
                strerror(errno));
        return 1;
    }
    if (check_configs(&s, scans, calibrations) != 0 || find_scanner(&s, www_given) != 0)
        return 2;
    char index[WEB_PATH + 16];
    snprintf(index, sizeof(index), "%s/index.html", s.www);
    if (access(index, R_OK) != 0) {
        fprintf(stderr, "scanner serve: %s: %s (--www DIR)\n", index, strerror(errno));
        return 2;
    }
    /* SIGINT and SIGTERM are waited for below, in this thread only */
    sigset_t stop;
    sigemptyset(&stop);
    sigaddset(&stop, SIGINT);
    sigaddset(&stop, SIGTERM);
    sigaddset(&stop, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &stop, NULL);
    signal(SIGPIPE, SIG_IGN);
    /* No CORS: civetweb answers pre-flights and adds Access-Control-Allow-Origin: * unless
     * told otherwise, which let any page start the rig. A request gets 10 s to arrive whole
     * and each write 10 s to drain (a slow or silent client frees its worker then). */
    char threads[16];
    snprintf(threads, sizeof(threads), "%u", WEB_THREADS);
    const char *options[] = {"listening_ports",
                             listen,
                             "document_root",
                             s.www,
                             "num_threads",
                             threads,
                             "enable_directory_listing",
                             "no",
                             "max_request_size",
                             "16384",
                             "request_timeout_ms",
                             "10000",
                             "access_control_allow_origin",
                             "",
                             "access_control_allow_methods",
                             "",
                             "access_control_allow_headers",
                             "",
                             "additional_header",
                             "X-Content-Type-Options: nosniff",
                             NULL};
    struct mg_callbacks callbacks;
    memset(&callbacks, 0, sizeof(callbacks));
    callbacks.log_message = log_message;
    mg_init_library(0);
    struct mg_context *ctx = mg_start(&callbacks, &s, options);
    if (ctx == NULL) {
        fprintf(stderr, "scanner serve: cannot listen on %s (in use? not an address here?)\n",
                listen);
        mg_exit_library();
        return 1;
    }
    mg_set_request_handler(ctx, "/api", api_handle, &s);
    printf("scanner serve: http://%s/ (%s; scans in %s%s)\n", listen, s.profile[0].path, s.scans,
           s.token[0] ? "; a token is required" : "");
    fflush(stdout);
    int sig = 0;
    sigwait(&stop, &sig);
    fprintf(stderr, "scanner-web: %s: shutting down\n", strsignal(sig));
    jobs_shutdown(&s); /* a scan stops in order: its views kept, the rig safe */
    mg_stop(ctx);
    mg_exit_library();
    return 0;
}
