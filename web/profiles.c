/* /api/profiles/NAME: a profile's main settings read and changed from the page (issue 32), each
 * change checked by the scanner's own key table (config_load, as check-config) before it is
 * kept: over the old file, which stays beside it as a backup, or as a new profile. */
#define _GNU_SOURCE
#include "api.h"

#include "config.h"
#include "file_posix.h"

#include <cJSON.h>
#include <civetweb.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* The keys the page may change: what a person tunes between objects. */
static const struct {
    const char *section, *key;
} editable[] = {
    {"scan", "views"},    {"scan", "passes"},        {"camera", "exposure_us"},
    {"colour", "method"}, {"output", "max_hole_mm"}, {"output", "watertight"},
};
#define EDITABLE (sizeof(editable) / sizeof(editable[0]))
#define PROFILE_MAX_FILE 65536 /* bytes of a config file the page edits */
#define PROFILE_MAX_VALUE 64

/* GET: {"name", "values": {"scan.views": "8", ...}} as the scanner reads them. */
static int get_profile(struct mg_connection *conn, const struct web_profile *p)
{
    struct app_config cfg;
    char err[WEB_PATH + 128], v[EDITABLE][PROFILE_MAX_VALUE];
    if (config_load(&cfg, p->path, err, sizeof(err)) != 0)
        return api_send_error(conn, 500, err);
    snprintf(v[0], sizeof(v[0]), "%u", (unsigned)cfg.views);
    snprintf(v[1], sizeof(v[1]), "%u", (unsigned)cfg.passes);
    snprintf(v[2], sizeof(v[2]), "%u", (unsigned)cfg.camera.exposure_us);
    snprintf(v[3], sizeof(v[3]), "%s", cfg.colour_method);
    snprintf(v[4], sizeof(v[4]), "%g", cfg.max_hole_mm);
    snprintf(v[5], sizeof(v[5]), "%u", (unsigned)cfg.watertight);
    cJSON *body = cJSON_CreateObject(), *values = cJSON_CreateObject();
    cJSON_AddStringToObject(body, "name", p->name);
    for (size_t k = 0; k < EDITABLE; k++) {
        char id[48];
        snprintf(id, sizeof(id), "%s.%s", editable[k].section, editable[k].key);
        cJSON_AddStringToObject(values, id, v[k]);
    }
    cJSON_AddItemToObject(body, "values", values);
    return api_send_json(conn, 200, body);
}

/* Whether @p line (length @p len) is "[section]". */
static int is_section(const char *line, size_t len, const char *section)
{
    size_t n = strlen(section);
    return len >= n + 2 && line[0] == '[' && strncmp(line + 1, section, n) == 0 &&
           line[n + 1] == ']';
}

/* Whether @p line is "key = ..." (spaces around). */
static int is_key(const char *line, size_t len, const char *key)
{
    size_t i = 0, n = strlen(key);
    while (i < len && (line[i] == ' ' || line[i] == '\t'))
        i++;
    if (len - i < n || strncmp(line + i, key, n) != 0)
        return 0;
    for (i += n; i < len && (line[i] == ' ' || line[i] == '\t'); i++)
        ;
    return i < len && line[i] == '=';
}

/* @p text (an INI file, in a buffer of @p cap bytes) with "key = value" in [section]: the key's
 * line replaced, or added after the section's header, or the section added at the end.
 * @retval 0 @retval -ENOSPC */
static int set_value(char *text, size_t cap, const char *section, const char *key,
                     const char *value)
{
    char line[160];
    int n = snprintf(line, sizeof(line), "%s = %s\n", key, value);
    size_t len = strlen(text), at = len, drop = 0;
    int in = 0, found = 0;
    for (size_t i = 0; i < len && !found;) {
        size_t e = i;
        while (e < len && text[e] != '\n')
            e++;
        size_t l = e - i;
        if (l > 0 && text[i] == '[') {
            in = is_section(text + i, l, section);
            if (in)
                at = e < len ? e + 1 : e; /* after the header, should the key be missing */
        } else if (in && is_key(text + i, l, key)) {
            at = i, drop = (e < len ? e + 1 : e) - i, found = 1;
        }
        i = e < len ? e + 1 : e;
    }
    char header[64] = "";
    if (at == len && !found && !in) /* no such section: add it */
        snprintf(header, sizeof(header), "%s[%s]\n", len > 0 && text[len - 1] != '\n' ? "\n" : "",
                 section);
    else if (at == len && len > 0 && text[len - 1] != '\n')
        snprintf(header, sizeof(header), "\n");
    size_t add = strlen(header) + (size_t)n;
    if (len - drop + add + 1 > cap)
        return -ENOSPC;
    memmove(text + at + add, text + at + drop, len - at - drop + 1);
    memcpy(text + at, header, strlen(header));
    memcpy(text + at + strlen(header), line, (size_t)n);
    return 0;
}

/* A value the page may write into a line of an INI file: one short line of plain text (no
 * comment or section it could start, nothing inih would read otherwise). */
static int value_ok(const char *v)
{
    size_t n = strlen(v);
    if (n == 0 || n >= PROFILE_MAX_VALUE)
        return 0;
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)v[i] < 0x20 || v[i] == 0x7f || strchr(";#[]=\\\"", v[i]) != NULL)
            return 0;
    return 1;
}

/* @p path's text into @p text (cap bytes): a regular file only (a pipe put in its place would
 * hold the request's thread). @retval 0 @retval -errno */
static int read_text(const char *path, char *text, size_t cap)
{
    FILE *f = file_open_regular(path, "r");
    if (f == NULL)
        return -errno;
    size_t n = fread(text, 1, cap - 1, f);
    int more = fgetc(f) != EOF;
    fclose(f);
    text[n] = '\0';
    return more || strlen(text) != n ? -EFBIG : 0;
}

/* @p text written whole as @p path (must not exist), fsynced. @retval 0 @retval -errno */
static int write_new(const char *path, const char *text)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd < 0)
        return -errno;
    size_t len = strlen(text);
    int ok = write(fd, text, len) == (ssize_t)len && fsync(fd) == 0;
    int e = errno;
    close(fd);
    if (!ok)
        unlink(path);
    return ok ? 0 : -e;
}

/* The change of @p body applied to @p text: 0, or an error answered (@retval its status). */
static int apply_values(struct mg_connection *conn, const cJSON *values, char *text, size_t cap)
{
    if (!cJSON_IsObject(values))
        return api_send_error(conn, 400, "send {\"values\": {\"scan.views\": \"12\", ...}}");
    const cJSON *v;
    cJSON_ArrayForEach(v, values)
    {
        size_t k = 0;
        char want[48];
        for (; k < EDITABLE; k++) {
            snprintf(want, sizeof(want), "%s.%s", editable[k].section, editable[k].key);
            if (strcmp(want, v->string) == 0)
                break;
        }
        char msg[200];
        if (k == EDITABLE) {
            snprintf(msg, sizeof(msg), "%.60s: not a setting the page may change", v->string);
            return api_send_error(conn, 400, msg);
        }
        if (!cJSON_IsString(v) || !value_ok(v->valuestring)) {
            snprintf(msg, sizeof(msg), "[%s] %s: one line of plain text, under %d characters",
                     editable[k].section, editable[k].key, PROFILE_MAX_VALUE);
            return api_send_error(conn, 400, msg);
        }
        if (set_value(text, cap, editable[k].section, editable[k].key, v->valuestring) != 0)
            return api_send_error(conn, 413, "the profile would grow too large");
    }
    return 0;
}

/* POST {"values": {...}, "save_as": "NAME2"}: checked, then kept. */
static int set_profile(struct mg_connection *conn, struct web_server *s,
                       const struct web_profile *p)
{
    cJSON *body = NULL;
    int st = api_read_body(conn, &body);
    char *text = malloc(PROFILE_MAX_FILE + 1024);
    char dir[WEB_PATH], tmp[WEB_PATH + 160], err[WEB_PATH + 512], target[WEB_PATH + 160];
    const cJSON *as = cJSON_GetObjectItemCaseSensitive(body, "save_as");
    if (st != 0 || text == NULL) {
        st = api_send_error(conn, st != 0 ? st : 500, "send the change as one JSON object");
        goto out_free;
    }
    if (as != NULL && (!cJSON_IsString(as) || !web_name_ok(as->valuestring) ||
                       strlen(as->valuestring) > 40 || strchr(as->valuestring, '.') != NULL)) {
        st = api_send_error(conn, 400, "save_as: a new profile's name, letters, digits, _ and -");
        goto out_free;
    }
    if (read_text(p->path, text, PROFILE_MAX_FILE) != 0) {
        st = api_send_error(conn, 500, "the profile's file cannot be read (or is over 64 KiB)");
        goto out_free;
    }
    if ((st = apply_values(conn, cJSON_GetObjectItemCaseSensitive(body, "values"), text,
                           PROFILE_MAX_FILE + 1024)) != 0)
        goto out_free;
    /* beside the old file, so that its relative paths (the calibration) mean the same */
    snprintf(dir, sizeof(dir), "%s", p->path);
    char *slash = strrchr(dir, '/');
    if (slash != NULL)
        *slash = '\0';
    /* one name a request: two changes at once never write each other's file */
    static unsigned long serial;
    unsigned long mine = __atomic_add_fetch(&serial, 1, __ATOMIC_RELAXED);
    if ((size_t)snprintf(tmp, sizeof(tmp), "%s/.%s.ini.%ld-%lu.tmp", dir, p->name, (long)getpid(),
                         mine) >= sizeof(tmp) ||
        (as != NULL && (size_t)snprintf(target, sizeof(target), "%s/%s.ini", dir,
                                        as->valuestring) >= sizeof(s->profile[0].path))) {
        st = api_send_error(conn, 500, "the profile's folder has too long a name");
        goto out_free;
    }
    int rc = write_new(tmp, text);
    struct app_config cfg;
    if (rc == 0 && config_load(&cfg, tmp, err, sizeof(err)) != 0) {
        unlink(tmp);
        /* the scanner's own words, naming the key, without the temporary file's name */
        const char *said = strstr(err, tmp) == err ? err + strlen(tmp) : err;
        said += strspn(said, ":0123456789 ");
        st = api_send_error(conn, 400, said);
        goto out_free;
    }
    if (rc != 0) {
        snprintf(err, sizeof(err), "the profile cannot be written in %s: %s", dir, strerror(-rc));
        st = api_send_error(conn, 500, err);
        goto out_free;
    }
    if (as != NULL) { /* a new profile: never over another file */
        pthread_mutex_lock(&s->job.lock);
        int full = s->profiles == WEB_MAX_PROFILES,
            taken = api_profile_named(s, as->valuestring) != NULL;
        rc = full || taken ? -EEXIST : link(tmp, target) == 0 ? 0 : -errno;
        if (rc == 0) { /* filled first, then counted: a reader sees it whole or not at all */
            struct web_profile *np = &s->profile[s->profiles];
            snprintf(np->name, sizeof(np->name), "%s", as->valuestring);
            memcpy(np->path, target, strlen(target) + 1); /* fits: checked above */
            s->profiles++;
        }
        pthread_mutex_unlock(&s->job.lock);
        unlink(tmp);
        st = rc == 0         ? api_send_json(conn, 200, cJSON_CreateObject())
             : rc == -EEXIST ? api_send_error(conn, 409,
                                              full ? "there are 16 profiles already"
                                                   : "a profile of that name exists")
                             : api_send_error(conn, 500, "the new profile cannot be written");
        goto out_free;
    }
    /* over the old file, which stays as NAME.ini.bak-DATE (a second name for it, then the new
     * file renamed over the first: at every moment one whole file has the profile's name) */
    char stamp[32];
    time_t now = time(NULL);
    struct tm tm;
    strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", localtime_r(&now, &tm));
    snprintf(target, sizeof(target), "%s.bak-%s", p->path, stamp);
    rc = link(p->path, target) == 0 || errno == EEXIST ? 0 : -errno;
    if (rc == 0 && rename(tmp, p->path) != 0)
        rc = -errno;
    if (rc != 0)
        unlink(tmp);
    st = rc == 0 ? api_send_json(conn, 200, cJSON_CreateObject())
                 : api_send_error(conn, 500, "the profile cannot be replaced");
out_free:
    free(text);
    cJSON_Delete(body);
    return st;
}

int profiles_handle(struct mg_connection *conn, struct web_server *s, const char *method,
                    const char *name)
{
    const struct web_profile *p = api_profile_named(s, name);
    int is_get = strcmp(method, "GET") == 0;
    if (p == NULL)
        return api_send_error(conn, 404, "no such profile (GET /api/status lists them)");
    if (is_get)
        return get_profile(conn, p);
    if (!api_may_use_rig(s, conn))
        return api_send_error(conn, 403, "changing a profile carries the session key");
    return set_profile(conn, s, p);
}
