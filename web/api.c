/* The HTTP API (docs/api.md): JSON in and out under /api, each request checked for its token
 * off loopback, its size and its path before anything is done for it. */
#define _GNU_SOURCE
#include "api.h"

#include "config.h"
#include "disk_room.h"
#include "guard.h"
#include "report.h"
#include "scan_dir.h"

#include <cJSON.h>
#include <civetweb.h>
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#ifndef SCANNER_VERSION
#define SCANNER_VERSION "0.1.0"
#endif

static const char *reason_phrase(int status)
{
    switch (status) {
    case 200:
        return "OK";
    case 400:
        return "Bad Request";
    case 401:
        return "Unauthorized";
    case 403:
        return "Forbidden";
    case 404:
        return "Not Found";
    case 405:
        return "Method Not Allowed";
    case 409:
        return "Conflict";
    case 413:
        return "Payload Too Large";
    case 415:
        return "Unsupported Media Type";
    case 429:
        return "Too Many Requests";
    case 503:
        return "Service Unavailable";
    case 507:
        return "Insufficient Storage";
    default:
        return "Internal Server Error";
    }
}

/* Send @p body (taken) with @p status. @retval the civetweb handler's "handled" (status) */
int api_send_json(struct mg_connection *conn, int status, cJSON *body)
{
    char *text = cJSON_PrintUnformatted(body);
    cJSON_Delete(body);
    if (text == NULL)
        return 500;
    /* the body with mg_write: civetweb 1.15's mg_printf fails on long output (it formats
     * twice with one va_list) */
    mg_printf(conn,
              "HTTP/1.1 %d %s\r\nContent-Type: application/json\r\nContent-Length: %zu\r\n"
              "Cache-Control: no-store\r\n\r\n",
              status, reason_phrase(status), strlen(text));
    mg_write(conn, text, strlen(text));
    free(text);
    return status;
}

int api_send_error(struct mg_connection *conn, int status, const char *message)
{
    cJSON *body = cJSON_CreateObject();
    cJSON_AddStringToObject(body, "error", message);
    return api_send_json(conn, status, body);
}

/* ---- who may ask ---- */

/* A script with the token in its Authorization header: no page of another site can send one. */
static int bearer(const struct web_server *s, const struct mg_connection *conn)
{
    const char *h = mg_get_header(conn, "Authorization");
    return s->token[0] != '\0' && h != NULL && strncmp(h, "Bearer ", 7) == 0 &&
           guard_secret_equal(h + 7, s->token);
}

/* Off loopback every API request but the login carries the token: an "Authorization: Bearer"
 * header (scripts), or the cookie the login sets (the page, and its downloads). */
static int authorised(const struct web_server *s, const struct mg_connection *conn)
{
    if (s->token[0] == '\0' || bearer(s, conn))
        return 1;
    const char *cookie = mg_get_header(conn, "Cookie");
    char value[sizeof(s->token)];
    return cookie != NULL && mg_get_cookie(cookie, "scanner_token", value, sizeof(value)) > 0 &&
           guard_secret_equal(value, s->token);
}

/* A request that uses the rig carries the session key (or a Bearer token). */
int api_may_use_rig(const struct web_server *s, const struct mg_connection *conn)
{
    return guard_has_key(s, conn) || bearer(s, conn);
}

int api_send_png(struct mg_connection *conn, const void *png, size_t len)
{
    mg_printf(conn,
              "HTTP/1.1 200 OK\r\nContent-Type: image/png\r\nContent-Length: %zu\r\n"
              "Cache-Control: no-store\r\n\r\n",
              len);
    mg_write(conn, png, len);
    return 200;
}

int api_send_body_error(struct mg_connection *conn, int status)
{
    return api_send_error(conn, status,
                          status == 415   ? "send the request as application/json"
                          : status == 413 ? "the request is too large"
                                          : "the body is not one JSON object (nested at most 32 "
                                            "deep, nothing after it)");
}

/* A POST's JSON body: application/json (which a page of another site cannot send here without
 * the browser asking first, so that no other site can start the rig from a visitor's browser)
 * and at most WEB_MAX_BODY bytes, nested at most GUARD_MAX_JSON_DEPTH deep (counted before
 * parsing: cJSON recurses once a level), one JSON object and nothing after it. An empty body is
 * {}. @retval 0 or the status to answer */
int api_read_body(struct mg_connection *conn, cJSON **body)
{
    const struct mg_request_info *ri = mg_get_request_info(conn);
    const char *type = mg_get_header(conn, "Content-Type");
    char text[WEB_MAX_BODY + 2];
    if (type == NULL || strncmp(type, "application/json", 16) != 0)
        return 415;
    if (ri->content_length > WEB_MAX_BODY)
        return 413;
    /* a chunked body says no length: one byte more than the limit tells it is too long */
    int n = 0, got;
    while (n <= WEB_MAX_BODY && (got = mg_read(conn, text + n, (size_t)(WEB_MAX_BODY + 1 - n))) > 0)
        n += got;
    if (n > WEB_MAX_BODY)
        return 413;
    text[n] = '\0';
    if (strlen(text) != (size_t)n) /* a NUL inside: what follows it would go unread */
        return 400;
    if (guard_json_too_deep(text, GUARD_MAX_JSON_DEPTH))
        return 400;
    const char *end = NULL;
    *body = n == 0 ? cJSON_CreateObject() : cJSON_ParseWithOpts(text, &end, 1);
    return *body != NULL && cJSON_IsObject(*body) ? 0 : 400;
}

/* ---- scans ---- */

static void add_warning(void *priv, const char *line)
{
    cJSON *list = priv;
    if (cJSON_GetArraySize(list) < (int)WEB_MAX_WARNINGS)
        cJSON_AddItemToArray(list, cJSON_CreateString(line));
}

/* A scan's warnings as it kept them (warnings.txt, a line each: the first WEB_MAX_WARNINGS,
 * each cut at WEB_WARNING_LEN bytes; up to 64 counted), for a scan this server does not run now. */
static void saved_warnings(cJSON *o, const char *scans, const char *id)
{
    char dir[WEB_PATH + 80];
    snprintf(dir, sizeof(dir), "%s/%s", scans, id);
    cJSON *list = cJSON_AddArrayToObject(o, "warnings");
    unsigned count = scan_dir_each_warning(dir, 64, WEB_WARNING_LEN, add_warning, list);
    cJSON_AddNumberToObject(o, "warning_count", count);
}

static cJSON *job_json(struct web_server *s, const char *id)
{
    enum web_state state;
    unsigned done, total;
    char error[512];
    if (jobs_describe(s, id, &state, &done, &total, error, sizeof(error)) != 0)
        return NULL;
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "id", id);
    cJSON_AddStringToObject(o, "state", web_state_name(state));
    cJSON_AddNumberToObject(o, "views_done", done);
    cJSON_AddNumberToObject(o, "views_total", total);
    cJSON_AddStringToObject(o, "error", error);
    struct web_job *j = &s->job;
    pthread_mutex_lock(&j->lock);
    int live = strcmp(j->id, id) == 0 && j->state != WEB_IDLE && j->kind == WEB_SCAN;
    if (live) {
        cJSON_AddStringToObject(o, "stage", j->stage);
        cJSON_AddNumberToObject(o, "stage_views_done", j->step_done);
        cJSON_AddStringToObject(o, "detail", j->detail);
        cJSON_AddNumberToObject(o, "elapsed_s", j->elapsed_s);
        cJSON_AddNumberToObject(o, "left_s", j->left_s);
        cJSON_AddStringToObject(o, "profile", j->profile);
        cJSON *warnings = cJSON_AddArrayToObject(o, "warnings");
        for (unsigned k = 0; k < j->warning_count && k < WEB_MAX_WARNINGS; k++)
            cJSON_AddItemToArray(warnings, cJSON_CreateString(j->warnings[k]));
        cJSON_AddNumberToObject(o, "warning_count", j->warning_count);
    }
    pthread_mutex_unlock(&j->lock);
    if (!live)
        saved_warnings(o, s->scans, id);
    char path[WEB_PATH + 80];
    snprintf(path, sizeof(path), "%s/%s/" SCAN_FILE_REPORT, s->scans, id);
    cJSON_AddBoolToObject(o, "report", access(path, F_OK) == 0);
    snprintf(path, sizeof(path), "%s/%s/" SCAN_FILE_MESH_GLB, s->scans, id);
    cJSON_AddBoolToObject(o, "glb", access(path, F_OK) == 0);
    snprintf(path, sizeof(path), "%s/%s/" SCAN_FILE_TEXTURE, s->scans, id);
    cJSON_AddBoolToObject(o, "texture", access(path, F_OK) == 0);
    char label[WEB_MAX_LABEL + 2];
    jobs_label(s, id, label, sizeof(label));
    cJSON_AddStringToObject(o, "label", label);
    return o;
}

static int by_name_newest_first(const void *a, const void *b)
{
    return strcmp(*(char *const *)b, *(char *const *)a);
}

/* Every scan folder, newest first: all names are read before sorting (the folder's own order
 * is none), up to WEB_MAX_LISTED; beyond that the oldest are left out, and the answer says so. */
#define WEB_MAX_LISTED 100000u
static int list_scans(struct mg_connection *conn, struct web_server *s)
{
    cJSON *list = cJSON_CreateArray();
    DIR *d = opendir(s->scans);
    char **names = NULL;
    size_t n = 0, cap = 0, seen = 0;
    for (struct dirent *e; d != NULL && (e = readdir(d)) != NULL;) {
        if (!web_name_ok(e->d_name) || seen++ >= WEB_MAX_LISTED)
            continue;
        if (n == cap) {
            size_t more = cap == 0 ? 256 : 2 * cap;
            char **grown = realloc(names, more * sizeof(*names));
            if (grown == NULL)
                break;
            names = grown;
            cap = more;
        }
        if ((names[n] = strdup(e->d_name)) != NULL)
            n++;
    }
    if (d != NULL)
        closedir(d);
    if (n > 0)
        qsort(names, n, sizeof(names[0]), by_name_newest_first);
    for (size_t i = 0; i < n; i++) {
        cJSON *o = job_json(s, names[i]);
        if (o != NULL)
            cJSON_AddItemToArray(list, o);
        free(names[i]);
    }
    free(names);
    cJSON *body = cJSON_CreateObject();
    cJSON_AddItemToObject(body, "scans", list);
    cJSON_AddBoolToObject(body, "complete", seen <= WEB_MAX_LISTED);
    return api_send_json(conn, 200, body);
}

const struct web_profile *api_profile_named(const struct web_server *s, const char *name)
{
    for (unsigned i = 0; i < s->profiles; i++)
        if (strcmp(s->profile[i].name, name) == 0)
            return &s->profile[i];
    return NULL;
}

const struct web_profile *api_find_profile(const struct web_server *s, const cJSON *body)
{
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(body, "profile");
    if (name == NULL)
        return &s->profile[0]; /* {}: the served config */
    return cJSON_IsString(name) ? api_profile_named(s, name->valuestring) : NULL;
}

/* The profile to resume scan @p id with: the first that takes views as the scan did (its own
 * config.ini; the scanner refuses any other). @p why says what differs when none does. */
static const struct web_profile *resume_profile(const struct web_server *s, const char *id,
                                                char *why, size_t why_len)
{
    struct app_config taken, profile;
    char path[WEB_PATH + 32], err[WEB_PATH + 128];
    const struct web_profile *found = NULL;
    if (jobs_scan_dir(s, id, path, sizeof(path)) != 0 ||
        strlen(path) + sizeof("/" SCAN_FILE_CONFIG) > sizeof(path)) {
        snprintf(why, why_len, "no such scan");
    } else {
        strcat(path, "/" SCAN_FILE_CONFIG);
        int loaded = config_load(&taken, path, err, sizeof(err)) == 0;
        if (!loaded)
            snprintf(why, why_len, "the scan's settings do not load: %s", err);
        for (unsigned i = 0; loaded && i < s->profiles && found == NULL; i++) {
            char what[160];
            if (config_load(&profile, s->profile[i].path, err, sizeof(err)) != 0)
                continue;
            config_adopt_chosen(&profile, &taken); /* as the scanner's resume will */
            if (config_plan_differs(&taken, &profile, 1, what, sizeof(what)) == 0)
                found = &s->profile[i];
            else if (why[0] == '\0')
                snprintf(why, why_len,
                         "no profile takes views as this scan did (%s: the scan "
                         "has %s)",
                         s->profile[i].name, what);
        }
        if (found != NULL)
            why[0] = '\0';
    }
    return found;
}

/* Whether the scans' disk holds what profile @p p's scan (or the views a resume of @p resume_id
 * still takes) will keep (disk_room_check); @p why says what is short. @retval 1 it does */
static int disk_holds(struct web_server *s, const struct web_profile *p, const char *resume_id,
                      char *why, size_t why_len)
{
    struct app_config cfg;
    char err[WEB_PATH + 128];
    if (config_load(&cfg, p->path, err, sizeof(err)) != 0)
        return 1; /* the scanner itself says what is wrong with the profile */
    unsigned views = cfg.views * cfg.passes, done = 0, total = 0;
    enum web_state state;
    char error[8];
    if (resume_id != NULL &&
        jobs_describe(s, resume_id, &state, &done, &total, error, sizeof(error)) == 0)
        views = total > done ? total - done : 0;
    return disk_room_check(&cfg, s->scans, views, why, why_len) == 0;
}

/* POST /api/scans (a new scan) or /api/scans/ID/resume. */
static int start_scan(struct mg_connection *conn, struct web_server *s, const char *resume_id)
{
    if (!api_may_use_rig(s, conn))
        return api_refuse_without_key(conn);
    cJSON *body = NULL;
    int status = api_read_body(conn, &body);
    if (status != 0) {
        cJSON_Delete(body);
        return api_send_body_error(conn, status);
    }
    char why[WEB_PATH + 256] = "";
    int named = cJSON_GetObjectItemCaseSensitive(body, "profile") != NULL;
    const struct web_profile *p = resume_id != NULL && !named
                                      ? resume_profile(s, resume_id, why, sizeof(why))
                                      : api_find_profile(s, body);
    cJSON_Delete(body);
    if (p == NULL && why[0] != '\0')
        return api_send_error(conn, 409, why);
    if (p == NULL)
        return api_send_error(conn, 400, "no such profile (GET /api/status lists them)");
    if (!disk_holds(s, p, resume_id, why, sizeof(why)))
        return api_send_error(conn, 507, why);
    char id[64], err[WEB_PATH + 128];
    int rc = jobs_start(s, p, resume_id, id, sizeof(id), err, sizeof(err));
    if (rc != 0)
        return api_send_error(conn, rc == -EBUSY ? 409 : 500, err);
    cJSON *answer = cJSON_CreateObject();
    cJSON_AddStringToObject(answer, "id", id);
    return api_send_json(conn, 200, answer);
}

/* stream_events once its stream is counted. */
static int stream_events_counted(struct mg_connection *conn, struct web_server *s, const char *id)
{
    struct web_job *j = &s->job;
    unsigned long seen = 0;
    mg_printf(conn, "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: "
                    "no-store\r\nConnection: close\r\n\r\n");
    for (;;) {
        pthread_mutex_lock(&j->lock);
        seen = j->seq; /* what happens from here on wakes the wait below */
        pthread_mutex_unlock(&j->lock);
        cJSON *o = job_json(s, id);
        if (o == NULL)
            break;
        const char *state = cJSON_GetObjectItemCaseSensitive(o, "state")->valuestring;
        int over = strcmp(state, "running") != 0;
        char *text = cJSON_PrintUnformatted(o);
        cJSON_Delete(o);
        int sent = text != NULL && mg_write(conn, "data: ", 6) > 0 &&
                           mg_write(conn, text, strlen(text)) > 0 && mg_write(conn, "\n\n", 2) > 0
                       ? 1
                       : -1;
        free(text);
        if (sent <= 0 || over)
            break;
        pthread_mutex_lock(&j->lock);
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_sec += 15; /* a comment now and then tells a dead client from a live one */
        int timed_out = 0;
        while (j->seq == seen && !j->stopping && !timed_out)
            timed_out = pthread_cond_timedwait(&j->changed, &j->lock, &until) == ETIMEDOUT;
        int stopping = j->stopping;
        pthread_mutex_unlock(&j->lock);
        if (stopping || (timed_out && mg_printf(conn, ": still here\n\n") <= 0))
            break;
    }
    return 200;
}

/* Server-Sent Events: the scan's state at every event, until it ends (or the client goes). Each
 * stream holds a worker thread: at most WEB_MAX_STREAMS at once, so that open tabs never take
 * the workers that status and stop need. */
static int stream_events(struct mg_connection *conn, struct web_server *s, const char *id)
{
    struct web_job *j = &s->job;
    pthread_mutex_lock(&j->lock);
    int full = s->streams >= WEB_MAX_STREAMS;
    s->streams += !full;
    pthread_mutex_unlock(&j->lock);
    if (full)
        return api_send_error(conn, 503,
                              "too many progress streams open (close a tab of the page)");
    int rc = stream_events_counted(conn, s, id);
    pthread_mutex_lock(&j->lock);
    s->streams--;
    pthread_mutex_unlock(&j->lock);
    return rc;
}

/* A file of the scan: one name, or a view folder and a name; never anything outside it. */
static int send_scan_file(struct mg_connection *conn, struct web_server *s, const char *id,
                          const char *rel)
{
    char part[2][160], path[PATH_MAX + 400], real[PATH_MAX], root[PATH_MAX];
    int parts = 0;
    for (const char *p = rel; parts < 3;) {
        size_t len = strcspn(p, "/");
        if (parts == 2 || len == 0 || len >= sizeof(part[0]))
            return api_send_error(conn, 403, "not a file of the scan");
        memcpy(part[parts], p, len);
        part[parts][len] = '\0';
        if (!web_name_ok(part[parts++]))
            return api_send_error(conn, 403, "not a file of the scan");
        if (p[len] == '\0')
            break;
        p += len + 1;
    }
    if (jobs_scan_dir(s, id, path, sizeof(path)) != 0 || realpath(path, root) == NULL)
        return api_send_error(conn, 404, "no such scan");
    if (parts == 1)
        snprintf(path, sizeof(path), "%s/%s", root, part[0]);
    else
        snprintf(path, sizeof(path), "%s/%s/%s", root, part[0], part[1]);
    struct stat sb;
    /* a link planted in the folder must not lead out of it */
    if (realpath(path, real) == NULL || stat(real, &sb) != 0 || !S_ISREG(sb.st_mode))
        return api_send_error(conn, 404, "no such file in the scan");
    if (strncmp(real, root, strlen(root)) != 0 || real[strlen(root)] != '/')
        return api_send_error(conn, 403, "not a file of the scan");
    const char *name = part[parts - 1], *dot = strrchr(name, '.');
    const char *mime = dot == NULL                 ? "application/octet-stream"
                       : strcmp(dot, ".html") == 0 ? "text/html; charset=utf-8"
                       : strcmp(dot, ".png") == 0  ? "image/png"
                       : strcmp(dot, ".glb") == 0  ? "model/gltf-binary"
                       : strcmp(dot, ".ini") == 0  ? "text/plain; charset=utf-8"
                                                   : "application/octet-stream";
    const struct mg_request_info *ri = mg_get_request_info(conn);
    char extra[512] = "";
    if (ri->query_string != NULL && strstr(ri->query_string, "download=1") != NULL)
        snprintf(extra, sizeof(extra), "Content-Disposition: attachment; filename=\"%s\"\r\n",
                 name);
    mg_send_mime_file2(conn, real, mime, extra[0] ? extra : NULL);
    return 200;
}

/* A view's thumbnail, drawn by the report's reentrant reader (requests in parallel). */

static int send_thumb(struct mg_connection *conn, struct web_server *s, const char *id,
                      const char *rest)
{
    unsigned view;
    char kind[16];
    if (sscanf(rest, "%u/%15[a-z].png", &view, kind) != 2)
        return api_send_error(conn, 404,
                              "no such thumbnail (VIEW/raw.png, colour.png, reasons.png)");
    enum report_thumb k = strcmp(kind, "raw") == 0      ? REPORT_THUMB_RAW
                          : strcmp(kind, "colour") == 0 ? REPORT_THUMB_INTRINSIC
                                                        : REPORT_THUMB_REASONS;
    if (k == REPORT_THUMB_REASONS && strcmp(kind, "reasons") != 0)
        return api_send_error(conn, 404, "no such thumbnail (raw, colour or reasons)");
    char dir[WEB_PATH + 160];
    if (jobs_scan_dir(s, id, dir, sizeof(dir)) != 0)
        return api_send_error(conn, 404, "no such scan");
    uint8_t *png = NULL;
    size_t len = 0;
    int rc = report_thumb_png(dir, view, k, &png, &len);
    if (rc != 0)
        return api_send_error(conn, 404, "that view has no such picture (yet)");
    api_send_png(conn, png, len);
    free(png);
    return 200;
}

/* The scan folder as one tar archive, streamed from tar(1) as it writes it. */
static int send_archive(struct mg_connection *conn, struct web_server *s, const char *id)
{
    struct web_job *j = &s->job;
    pthread_mutex_lock(&j->lock);
    int running = j->state == WEB_RUNNING && strcmp(j->id, id) == 0;
    pthread_mutex_unlock(&j->lock);
    if (running)
        return api_send_error(conn, 409, "the scan is still running");
    char name[160], dir[WEB_PATH + 160];
    if (jobs_scan_dir(s, id, dir, sizeof(dir)) != 0)
        return api_send_error(conn, 404, "no such scan");
    snprintf(name, sizeof(name), "%s/", id);
    /* "--": a name is never an option of tar's, whatever it begins with */
    const char *args[] = {"/bin/tar", "-C", s->scans, "-cf", "-", "--", name, NULL};
    int fd;
    pid_t pid = web_spawn(args, NULL, &fd, NULL);
    if (pid < 0)
        return api_send_error(conn, 500, "cannot run tar");
    char header[512];
    snprintf(header, sizeof(header),
             "HTTP/1.1 200 OK\r\nContent-Type: application/x-tar\r\nContent-Disposition: "
             "attachment; filename=\"%s.tar\"\r\nConnection: close\r\n\r\n",
             id);
    mg_printf(conn, "%s", header);
    /* (not on the stack: civetweb's worker threads have 100 KiB) */
    const size_t chunk = 65536;
    char *buf = malloc(chunk);
    ssize_t n;
    while (buf != NULL && ((n = read(fd, buf, chunk)) > 0 || (n < 0 && errno == EINTR)))
        if (n > 0 && mg_write(conn, buf, (size_t)n) <= 0)
            break; /* the client went away: tar gets SIGPIPE at its next write */
    free(buf);
    close(fd);
    waitpid(pid, NULL, 0);
    return 200;
}

/* POST /api/selftest: the rig's devices, each tried (not while a scan runs: the rig is one). */
static int selftest(struct mg_connection *conn, struct web_server *s)
{
    const char *args[] = {s->scanner, "selftest", "--config", s->profile[0].path, NULL};
    static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER; /* one self-test: the rig is one */
    char out[8192];
    int status = -1;
    pthread_mutex_lock(&lock);
    int rc = jobs_run_tool(s, args, out, sizeof(out), &status);
    cJSON *body = cJSON_CreateObject();
    cJSON_AddBoolToObject(body, "ok", rc == 0 && status == 0);
    cJSON_AddStringToObject(body, "table", rc == 0 ? out : "");
    pthread_mutex_unlock(&lock);
    if (rc == -EBUSY) {
        cJSON_Delete(body);
        return api_send_error(conn, 409, "the rig is busy (a scan is running)");
    }
    return api_send_json(conn, 200, body);
}

/* The profile and exposure a picture is taken with: none given (no body), the first profile at
 * its own exposure; {"profile": NAME, "exposure_us": N} to judge an exposure before it is saved.
 * @retval 0 @retval the status sent */
static int snapshot_settings(struct mg_connection *conn, const struct web_server *s,
                             const struct web_profile **p, char *exposure, size_t len)
{
    *p = &s->profile[0];
    exposure[0] = '\0';
    if (mg_get_header(conn, "Content-Type") == NULL &&
        mg_get_request_info(conn)->content_length <= 0)
        return 0;
    cJSON *body = NULL;
    int status = api_read_body(conn, &body);
    if (status != 0) {
        cJSON_Delete(body);
        return api_send_body_error(conn, status);
    }
    const cJSON *e = cJSON_GetObjectItemCaseSensitive(body, "exposure_us");
    *p = api_find_profile(s, body);
    int ok = e == NULL || (cJSON_IsNumber(e) && e->valuedouble >= 10 && e->valuedouble <= 1e7 &&
                           e->valuedouble == (double)(long)e->valuedouble);
    if (ok && e != NULL)
        snprintf(exposure, len, "%ld", (long)e->valuedouble);
    cJSON_Delete(body);
    if (*p == NULL)
        return api_send_error(conn, 400, "no such profile (GET /api/status lists them)");
    if (!ok)
        return api_send_error(conn, 400,
                              "exposure_us: a whole number of microseconds from 10 "
                              "to 10000000");
    return 0;
}

/* POST /api/snapshot.png: what the camera sees lit by the projector's white. */
static int snapshot(struct mg_connection *conn, struct web_server *s)
{
    const struct web_profile *p;
    char exposure[16];
    int st = snapshot_settings(conn, s, &p, exposure, sizeof(exposure));
    if (st != 0)
        return st;
    char path[] = "/tmp/scanner-snapshot-XXXXXX.png", out[512];
    int fd = mkstemps(path, 4);
    if (fd < 0)
        return api_send_error(conn, 500, "cannot make a temporary file");
    close(fd);
    const char *args[] = {s->scanner,
                          "snapshot",
                          "--config",
                          p->path,
                          "--out",
                          path,
                          exposure[0] ? "--exposure-us" : NULL,
                          exposure,
                          NULL};
    int status = -1;
    int rc = jobs_run_tool(s, args, out, sizeof(out), &status);
    if (rc == -EBUSY) {
        unlink(path);
        return api_send_error(conn, 409, "the rig is busy (a scan or a calibration is running)");
    }
    if (rc != 0 || status != 0) {
        unlink(path);
        return api_send_error(conn, 500, "the camera gave no picture (GET /api/selftest says why)");
    }
    mg_send_mime_file2(conn, path, "image/png", "Cache-Control: no-store\r\n");
    unlink(path);
    return 200;
}

static int status(struct mg_connection *conn, struct web_server *s)
{
    struct web_job *j = &s->job;
    cJSON *body = cJSON_CreateObject(), *profiles = cJSON_CreateArray();
    cJSON_AddStringToObject(body, "version", SCANNER_VERSION);
    for (unsigned i = 0; i < s->profiles; i++)
        cJSON_AddItemToArray(profiles, cJSON_CreateString(s->profile[i].name));
    cJSON_AddItemToObject(body, "profiles", profiles);
    pthread_mutex_lock(&j->lock);
    int running = j->state == WEB_RUNNING && j->kind == WEB_SCAN, busy = j->rig_busy;
    int calibrating = j->state == WEB_RUNNING && j->kind != WEB_SCAN;
    char id[64];
    snprintf(id, sizeof(id), "%s", j->id);
    pthread_mutex_unlock(&j->lock);
    cJSON_AddBoolToObject(body, "scanning", running);
    cJSON_AddBoolToObject(body, "calibrating", calibrating);
    cJSON_AddStringToObject(body, "current", running ? id : "");
    /* every scanner command leaves lights and projector off when it ends: while none runs,
     * they are off */
    cJSON_AddStringToObject(body, "lights_and_projector",
                            busy ? "switched by the scanner as it works" : "off");
    cJSON_AddBoolToObject(body, "token_required", s->token[0] != '\0');
    struct statvfs fs;
    if (statvfs(s->scans, &fs) == 0) { /* what a person may use: the blocks free to them */
        cJSON_AddNumberToObject(body, "disk_free_bytes", (double)fs.f_bavail * fs.f_frsize);
        cJSON_AddNumberToObject(body, "disk_total_bytes", (double)fs.f_blocks * fs.f_frsize);
    }
    return api_send_json(conn, 200, body);
}

/* GET /api/session: the key that requests using the rig carry (X-Scanner-Key). Only a page of
 * this server can read the answer: a page of another site gets no CORS permission, and its
 * requests are refused before they get here (guard_request). */
static int session(struct mg_connection *conn, struct web_server *s)
{
    cJSON *body = cJSON_CreateObject();
    cJSON_AddStringToObject(body, "key", s->key);
    cJSON_AddStringToObject(body, "header", GUARD_KEY_HEADER);
    return api_send_json(conn, 200, body);
}

int api_refuse_without_key(struct mg_connection *conn)
{
    return api_send_error(conn, 403,
                          "a request that uses the rig carries the session key "
                          "(" GUARD_KEY_HEADER ": GET /api/session gives it)");
}

/* POST /api/login {"token": "..."}: the cookie the page's requests then carry. Its rate is
 * bounded and every wrong token is logged. */
static int login(struct mg_connection *conn, struct web_server *s)
{
    int st = guard_login_allowed(conn);
    if (st != 0)
        return api_send_error(conn, st, "too many wrong tokens just now: wait a few seconds");
    cJSON *body = NULL;
    st = api_read_body(conn, &body);
    const cJSON *token = cJSON_GetObjectItemCaseSensitive(body, "token");
    int ok = st == 0 && cJSON_IsString(token) && s->token[0] != '\0' &&
             guard_secret_equal(token->valuestring, s->token);
    cJSON_Delete(body);
    if (st != 0)
        return api_send_error(conn, st, "send {\"token\": \"...\"} as application/json");
    if (!ok) {
        guard_login_failed(conn);
        return api_send_error(conn, 401, "wrong token");
    }
    mg_printf(conn,
              "HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nContent-Length: 2\r\n"
              "Set-Cookie: scanner_token=%s; Path=/; HttpOnly; SameSite=Strict\r\n\r\n{}",
              s->token);
    return 200;
}

/* A label a person may give a scan: at most WEB_MAX_LABEL bytes, one line of text (no
 * control characters: the page shows it as text, a file keeps it as a line). */
static int label_ok(const char *label)
{
    size_t n = strlen(label);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)label[i] < 0x20 || label[i] == 0x7f)
            return 0;
    return n <= WEB_MAX_LABEL;
}

/* POST /api/scans/ID/label {"label": "..."} */
static int set_label(struct mg_connection *conn, struct web_server *s, const char *id)
{
    cJSON *body = NULL;
    int st = api_read_body(conn, &body);
    const cJSON *label = cJSON_GetObjectItemCaseSensitive(body, "label");
    int ok = st == 0 && cJSON_IsString(label) && label_ok(label->valuestring);
    int rc = ok ? jobs_set_label(s, id, label->valuestring) : 0;
    cJSON_Delete(body);
    if (!ok)
        return api_send_error(conn, st != 0 ? st : 400,
                              "send {\"label\": \"...\"}: one line, at most " WEB_MAX_LABEL_TEXT
                              " bytes");
    if (rc == -ENOENT)
        return api_send_error(conn, 404, "no such scan");
    return rc == 0 ? api_send_json(conn, 200, cJSON_CreateObject())
                   : api_send_error(conn, 500, "the label could not be written");
}

/* POST /api/scans/ID/delete: the scan's folder and everything in it, unless it runs. */
static int delete_scan(struct mg_connection *conn, struct web_server *s, const char *id)
{
    int rc = jobs_delete(s, id);
    if (rc == -EBUSY)
        return api_send_error(conn, 409, "that scan is running: stop it first");
    if (rc == -ENOENT)
        return api_send_error(conn, 404, "no such scan");
    return rc == 0 ? api_send_json(conn, 200, cJSON_CreateObject())
                   : api_send_error(conn, 500,
                                    "the scan could not be removed wholly (the server's "
                                    "log says what is left)");
}

/* /api/scans/ID[/what[/rest]] */
static int scan_route(struct mg_connection *conn, struct web_server *s, const char *method,
                      const char *path)
{
    char id[130];
    size_t len = strcspn(path, "/");
    if (len >= sizeof(id))
        return api_send_error(conn, 404, "no such scan");
    memcpy(id, path, len);
    id[len] = '\0';
    if (!web_name_ok(id))
        return api_send_error(conn, 403, "not a scan's name");
    const char *what = path[len] == '/' ? path + len + 1 : "";
    int is_get = strcmp(method, "GET") == 0, is_post = strcmp(method, "POST") == 0;
    if (what[0] == '\0' && is_get) {
        cJSON *o = job_json(s, id);
        return o != NULL ? api_send_json(conn, 200, o) : api_send_error(conn, 404, "no such scan");
    }
    int changes = strcmp(what, "stop") == 0 || strcmp(what, "delete") == 0 ||
                  strcmp(what, "label") == 0 ||
                  strcmp(what, "continue") == 0; /* what a page of another site must not do */
    if (changes && is_post && !api_may_use_rig(s, conn))
        return api_refuse_without_key(conn);
    if (strcmp(what, "delete") == 0 && is_post)
        return delete_scan(conn, s, id);
    if (strcmp(what, "continue") == 0 && is_post) {
        int rc = jobs_answer(s, WEB_SCAN, id, "continue");
        return rc == 0        ? api_send_json(conn, 200, cJSON_CreateObject())
               : rc == -ESRCH ? api_send_error(conn, 409, "that scan is not running")
               : rc == -EBUSY ? api_send_error(conn, 409,
                                               "the scan is not waiting for the object "
                                               "to be laid (or has its answer)")
                              : api_send_error(conn, 500, "the scanner has gone");
    }
    if (strcmp(what, "label") == 0 && is_post)
        return set_label(conn, s, id);
    if (strcmp(what, "stop") == 0 && is_post)
        return jobs_stop(s, WEB_SCAN, id) == 0
                   ? api_send_json(conn, 200, cJSON_CreateObject())
                   : api_send_error(conn, 409, "that scan is not running");
    if (strcmp(what, "resume") == 0 && is_post) {
        cJSON *o = job_json(s, id);
        int ok = o != NULL;
        cJSON_Delete(o);
        return ok ? start_scan(conn, s, id) : api_send_error(conn, 404, "no such scan");
    }
    if (strcmp(what, "events") == 0 && is_get)
        return stream_events(conn, s, id);
    if (strncmp(what, "files/", 6) == 0 && is_get)
        return send_scan_file(conn, s, id, what + 6);
    if (strncmp(what, "thumbs/", 7) == 0 && is_get)
        return send_thumb(conn, s, id, what + 7);
    if (strcmp(what, "archive.tar") == 0 && is_get)
        return send_archive(conn, s, id);
    return api_send_error(conn, is_get || is_post ? 404 : 405, "no such request");
}

int api_handle(struct mg_connection *conn, void *cbdata)
{
    struct web_server *s = cbdata;
    const struct mg_request_info *ri = mg_get_request_info(conn);
    /* the path as sent, decoded: the checks below see a "..", civetweb's cleaning would hide it */
    const char *path = ri->local_uri_raw != NULL ? ri->local_uri_raw : ri->local_uri;
    const char *method = ri->request_method;
    const char *why = NULL;
    int is_get = strcmp(method, "GET") == 0, is_post = strcmp(method, "POST") == 0;
    int refused = guard_request(s, conn, &why);
    if (refused != 0)
        return api_send_error(conn, refused, why);
    if (!is_get && !is_post) /* OPTIONS too: no CORS pre-flight is ever answered yes */
        return api_send_error(conn, 405, "GET or POST only");
    if (strcmp(path, "/api/login") == 0 && is_post)
        return login(conn, s);
    if (!authorised(s, conn))
        return api_send_error(conn, 401, "this scanner wants its token (POST /api/login)");
    if (strcmp(path, "/api/status") == 0 && is_get)
        return status(conn, s);
    if (strcmp(path, "/api/session") == 0 && is_get)
        return session(conn, s);
    int device = strcmp(path, "/api/selftest") == 0 || strcmp(path, "/api/snapshot.png") == 0;
    if (device && !is_post)
        return api_send_error(conn, 405, "POST: it uses the rig");
    if (device && !api_may_use_rig(s, conn))
        return api_refuse_without_key(conn);
    if (strcmp(path, "/api/selftest") == 0)
        return selftest(conn, s);
    if (strcmp(path, "/api/snapshot.png") == 0)
        return snapshot(conn, s);
    if (strcmp(path, "/api/scans") == 0 && is_get)
        return list_scans(conn, s);
    if (strcmp(path, "/api/scans") == 0 && is_post)
        return start_scan(conn, s, NULL);
    if (strncmp(path, "/api/scans/", 11) == 0)
        return scan_route(conn, s, method, path + 11);
    if (strncmp(path, "/api/profiles/", 14) == 0)
        return profiles_handle(conn, s, method, path + 14);
    if (strcmp(path, "/api/calibration") == 0 || strncmp(path, "/api/calibration/", 17) == 0)
        return calibration_handle(conn, s, method, path + 16);
    return api_send_error(conn, 404, "no such request (docs/api.md)");
}
