/* /api/calibration: the calibration wizard of the page (issue 32). `scanner calibrate --json`
 * runs as the rig's job (the same procedure as at a terminal); its questions are answered from
 * the page, only with the answers each names; its result is shown beside the file in use and
 * put in that file's place on the person's word, the old file kept beside it (docs/api.md). */
#define _GNU_SOURCE
#include "api.h"

#include "calib_file.h"
#include "config.h"
#include "file_posix.h"
#include "storage_posix.h"

#include <cJSON.h>
#include <civetweb.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define CAL_MAX_FILE                                                                               \
    (4u << 20) /* bytes of a calibration file, report or picture served or copied */

/* {"fx_px", "fy_px", "cx_px", "cy_px"} of a lens. */
static cJSON *lens_json(double fx, double fy, double cx, double cy)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "fx_px", fx);
    cJSON_AddNumberToObject(o, "fy_px", fy);
    cJSON_AddNumberToObject(o, "cx_px", cx);
    cJSON_AddNumberToObject(o, "cy_px", cy);
    return o;
}

/* What the calibration file @p path holds, for the page beside a new result: the lenses, the
 * pose's baseline, the axis, the RMS scanner calibrate recorded and whether it was flagged weak.
 * {"file", "missing": true} when there is none yet; {"file", "error"} when it does not load. */
static cJSON *file_summary(const char *path, uint32_t light_count)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "file", path);
    struct scan_calib *c = malloc(sizeof(*c));
    char err[WEB_PATH + 256], why[512];
    struct stat sb;
    if (stat(path, &sb) != 0) {
        cJSON_AddBoolToObject(o, "missing", 1);
    } else if (c == NULL || calib_load(c, path, light_count, err, sizeof(err)) != 0) {
        cJSON_AddStringToObject(o, "error", c == NULL ? "out of memory" : err);
    } else {
        char when[32];
        struct tm tm;
        gmtime_r(&sb.st_mtime, &tm);
        strftime(when, sizeof(when), "%Y-%m-%d %H:%M UTC", &tm);
        cJSON_AddStringToObject(o, "modified", when);
        cJSON_AddItemToObject(o, "camera",
                              lens_json(c->cam_fx_px, c->cam_fy_px, c->cam_cx_px, c->cam_cy_px));
        cJSON_AddItemToObject(
            o, "projector", lens_json(c->proj_fx_px, c->proj_fy_px, c->proj_cx_px, c->proj_cy_px));
        cJSON_AddItemToObject(o, "translation_mm", cJSON_CreateDoubleArray(c->proj_trans_mm, 3));
        cJSON *axis = cJSON_CreateObject();
        cJSON_AddItemToObject(axis, "point_mm", cJSON_CreateDoubleArray(c->axis_point_mm, 3));
        cJSON_AddItemToObject(axis, "dir", cJSON_CreateDoubleArray(c->axis_dir, 3));
        cJSON_AddItemToObject(o, "axis", axis);
        double cam_rms, proj_rms;
        calib_read_quality(path, &cam_rms, &proj_rms);
        if (cam_rms >= 0.0) {
            cJSON_AddNumberToObject(o, "camera_rms_px", cam_rms);
            cJSON_AddNumberToObject(o, "projector_rms_px", proj_rms);
        }
        cJSON_AddStringToObject(o, "weak", calib_read_weak(path, why, sizeof(why)) ? why : "");
    }
    free(c);
    return o;
}

/* The profile named @p name (none: the first), its config loaded into @p cfg.
 * @retval the profile @retval NULL no such one, or its config does not load (@p err) */
static const struct web_profile *profile_config(const struct web_server *s, const char *name,
                                                struct app_config *cfg, char *err, size_t err_len)
{
    const struct web_profile *p = name[0] != '\0' ? api_profile_named(s, name) : &s->profile[0];
    if (p == NULL) {
        snprintf(err, err_len, "no such profile");
        return NULL;
    }
    return config_load(cfg, p->path, err, err_len) == 0 ? p : NULL;
}

/* The job's events, one JSON object a line, as an array (a line that does not parse is left
 * out: the scanner writes whole lines, a cut one is not shown half). */
static cJSON *events_json(const char *log)
{
    cJSON *list = cJSON_CreateArray();
    for (const char *line = log; *line != '\0';) {
        const char *nl = strchr(line, '\n');
        size_t len = nl != NULL ? (size_t)(nl - line) : strlen(line);
        cJSON *ev = cJSON_ParseWithLength(line, len);
        if (ev != NULL)
            cJSON_AddItemToArray(list, ev);
        line += len + (nl != NULL);
    }
    return list;
}

/* What the calibration job holds, copied under its lock (the log is large: on the heap). */
struct snapshot {
    enum web_kind kind;
    enum web_state state;
    int asking;
    unsigned answers, pictures;
    char answer[WEB_MAX_ANSWERS][WEB_MAX_ANSWER];
    char id[64], profile[64], stage[32], detail[512], error[512], choice[16];
    char live[1024], result[WEB_CALIB_RESULT], log[WEB_CALIB_LOG];
};

/* @retval 1 the last job of the rig was a calibration or a verification (@p out holds it) */
static int take_snapshot(struct web_server *s, struct snapshot *out)
{
    struct web_job *j = &s->job;
    pthread_mutex_lock(&j->lock);
    int have = j->state != WEB_IDLE && j->kind != WEB_SCAN;
    if (have) {
        out->kind = j->kind;
        out->state = j->state;
        out->asking = j->state == WEB_RUNNING && j->answers > 0 && !j->answered;
        out->answers = j->answers;
        out->pictures = j->calib_pictures;
        memcpy(out->answer, j->answer, sizeof(out->answer));
        snprintf(out->id, sizeof(out->id), "%s", j->id);
        snprintf(out->profile, sizeof(out->profile), "%s", j->profile);
        snprintf(out->stage, sizeof(out->stage), "%s", j->stage);
        snprintf(out->detail, sizeof(out->detail), "%s", j->detail);
        snprintf(out->error, sizeof(out->error), "%s", j->error);
        snprintf(out->choice, sizeof(out->choice), "%s", j->calib_choice);
        memcpy(out->live, j->calib_live, sizeof(out->live));
        memcpy(out->result, j->calib_result, sizeof(out->result));
        memcpy(out->log, j->calib_log, j->calib_log_len + 1);
    }
    pthread_mutex_unlock(&j->lock);
    return have;
}

/* GET /api/calibration[?profile=NAME]: the calibration that runs or ran last (its steps, the
 * question it asks, the last live picture's corners, its result) and the file in use. */
static int get_state(struct mg_connection *conn, struct web_server *s)
{
    struct snapshot *sn = malloc(sizeof(*sn));
    if (sn == NULL)
        return api_send_error(conn, 500, "out of memory");
    char name[64] = "", err[WEB_PATH + 256];
    const struct mg_request_info *ri = mg_get_request_info(conn);
    if (ri->query_string != NULL)
        mg_get_var(ri->query_string, strlen(ri->query_string), "profile", name, sizeof(name));
    cJSON *o = cJSON_CreateObject();
    int have = take_snapshot(s, sn);
    if (!have) {
        cJSON_AddStringToObject(o, "state", "idle");
    } else {
        cJSON_AddStringToObject(o, "id", sn->id);
        cJSON_AddStringToObject(o, "kind", sn->kind == WEB_VERIFY ? "verify" : "calibration");
        cJSON_AddStringToObject(o, "state", web_state_name(sn->state));
        cJSON_AddStringToObject(o, "profile", sn->profile);
        cJSON_AddStringToObject(o, "stage", sn->stage);
        cJSON_AddStringToObject(o, "error", sn->error);
        cJSON_AddStringToObject(o, "choice", sn->choice);
        cJSON_AddNumberToObject(o, "pictures", sn->pictures);
        cJSON *q = cJSON_CreateObject(), *answers = cJSON_CreateArray();
        for (unsigned k = 0; sn->asking && k < sn->answers; k++)
            cJSON_AddItemToArray(answers, cJSON_CreateString(sn->answer[k]));
        cJSON_AddStringToObject(q, "detail", sn->detail);
        cJSON_AddItemToObject(q, "answers", answers);
        cJSON_AddItemToObject(o, "question", sn->asking ? q : cJSON_CreateNull());
        if (!sn->asking)
            cJSON_Delete(q);
        cJSON_AddItemToObject(o, "events", events_json(sn->log));
        cJSON *live = cJSON_Parse(sn->live), *result = cJSON_Parse(sn->result);
        cJSON_AddItemToObject(o, "live", live != NULL ? live : cJSON_CreateNull());
        cJSON_AddItemToObject(o, "result", result != NULL ? result : cJSON_CreateNull());
        if (name[0] == '\0')
            snprintf(name, sizeof(name), "%s", sn->profile);
    }
    struct app_config cfg;
    if (profile_config(s, name, &cfg, err, sizeof(err)) != NULL)
        cJSON_AddItemToObject(o, "in_use", file_summary(cfg.calibration_file, cfg.light_count));
    free(sn);
    return api_send_json(conn, 200, o);
}

/* POST /api/calibration or /api/calibration/verify {"profile": NAME}: start one. */
static int start(struct mg_connection *conn, struct web_server *s, int verify)
{
    cJSON *body = NULL;
    int status = api_read_body(conn, &body);
    if (status != 0) {
        cJSON_Delete(body);
        return api_send_body_error(conn, status);
    }
    const struct web_profile *p = api_find_profile(s, body);
    cJSON_Delete(body);
    if (p == NULL)
        return api_send_error(conn, 400, "no such profile (GET /api/status lists them)");
    struct app_config cfg;
    char err[WEB_PATH + 256], id[64];
    if (config_load(&cfg, p->path, err, sizeof(err)) != 0)
        return api_send_error(conn, 400, err);
    int rc = jobs_start_calibration(s, p, verify, cfg.calibration_file, id, sizeof(id), err,
                                    sizeof(err));
    if (rc != 0)
        return api_send_error(conn, rc == -EBUSY ? 409 : 500, err);
    cJSON *answer = cJSON_CreateObject();
    cJSON_AddStringToObject(answer, "id", id);
    return api_send_json(conn, 200, answer);
}

/* The kind and id of the calibration job that runs. @retval 0 @retval -ESRCH none */
static int running(struct web_server *s, enum web_kind *kind, char *id, size_t len)
{
    struct web_job *j = &s->job;
    pthread_mutex_lock(&j->lock);
    int rc = j->state == WEB_RUNNING && j->kind != WEB_SCAN ? 0 : -ESRCH;
    *kind = j->kind;
    snprintf(id, len, "%s", j->id);
    pthread_mutex_unlock(&j->lock);
    return rc;
}

/* POST /api/calibration/answer {"answer": WORD}: one of the answers the question names. */
static int answer(struct mg_connection *conn, struct web_server *s)
{
    cJSON *body = NULL;
    int status = api_read_body(conn, &body);
    if (status != 0) {
        cJSON_Delete(body);
        return api_send_body_error(conn, status);
    }
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(body, "answer");
    enum web_kind kind;
    char id[64], word[WEB_MAX_ANSWER];
    int ok = cJSON_IsString(a) && strlen(a->valuestring) < sizeof(word);
    snprintf(word, sizeof(word), "%s", ok ? a->valuestring : "");
    cJSON_Delete(body);
    if (!ok)
        return api_send_error(conn, 400, "send {\"answer\": \"...\"}, one the question names");
    int rc = running(s, &kind, id, sizeof(id));
    if (rc == 0)
        rc = jobs_answer(s, kind, id, word);
    return rc == 0         ? api_send_json(conn, 200, cJSON_CreateObject())
           : rc == -ESRCH  ? api_send_error(conn, 409, "no calibration is running")
           : rc == -EBUSY  ? api_send_error(conn, 409,
                                            "the calibration asks nothing now (or has "
                                             "its answer)")
           : rc == -EINVAL ? api_send_error(conn, 400,
                                            "not an answer this question takes (GET "
                                            "/api/calibration names them)")
                           : api_send_error(conn, 500, "the scanner has gone");
}

/* @p src copied whole to @p dst, bounded, durably and atomically (the storage layer's temporary
 * file, fsync, rename). @retval 0 @retval -errno */
static int copy_file(const char *src, const char *dst)
{
    FILE *in = file_open_regular(src, "rb");
    char *text = malloc(CAL_MAX_FILE);
    size_t n = in != NULL && text != NULL ? fread(text, 1, CAL_MAX_FILE, in) : 0;
    int rc = in == NULL                        ? -errno
             : text == NULL                    ? -ENOMEM
             : ferror(in) || n == CAL_MAX_FILE ? -EFBIG
                                               : 0;
    if (in != NULL)
        fclose(in);
    struct hal_storage st;
    storage_posix_init(&st);
    if (rc == 0)
        rc = hal_storage_write_file(&st, dst, text, n);
    free(text);
    return rc;
}

/* The new calibration @p fresh in the place of @p target, which (when there) stays beside it
 * as TARGET.YYYYmmddTHHMMSSZ as scanner calibrate keeps it; its report beside it too. Checked
 * by calib_load first: only a file that loads replaces the one in use.
 * @param kept  out: the old file's new name ("" none) @retval 0 @retval -errno (@p err) */
static int install(const char *fresh, const char *target, uint32_t light_count, char *kept,
                   size_t kept_len, char *err, size_t err_len)
{
    struct scan_calib *c = malloc(sizeof(*c));
    char report_from[WEB_PATH + 32], report_to[WEB_PATH + 32], stamp[32];
    int rc = c == NULL ? -ENOMEM : calib_load(c, fresh, light_count, err, err_len);
    free(c);
    kept[0] = '\0';
    if (rc != 0)
        return rc;
    time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    strftime(stamp, sizeof(stamp), "%Y%m%dT%H%M%SZ", &tm);
    if (access(target, F_OK) == 0) {
        snprintf(kept, kept_len, "%s.%s", target, stamp);
        if (link(target, kept) != 0) { /* a link: the file in use is never missing */
            rc = -errno;
            snprintf(err, err_len, "cannot keep the old %s as %s: %s", target, kept, strerror(-rc));
            kept[0] = '\0';
            return rc;
        }
    }
    if ((rc = copy_file(fresh, target)) != 0) {
        snprintf(err, err_len, "cannot write %s: %s", target, strerror(-rc));
        if (kept[0] != '\0')
            unlink(kept);
        kept[0] = '\0';
        return rc;
    }
    calib_path_beside(fresh, ".report.txt", report_from, sizeof(report_from));
    calib_path_beside(target, ".report.txt", report_to, sizeof(report_to));
    if (copy_file(report_from, report_to) != 0)
        fprintf(stderr, "scanner-web: the report %s was not copied beside %s\n", report_from,
                target);
    return 0;
}

/* POST /api/calibration/use or /keep: what to do with the calibration that finished. */
static int choose(struct mg_connection *conn, struct web_server *s, int use)
{
    struct web_job *j = &s->job;
    char dir[WEB_PATH], file[WEB_PATH], profile[64];
    pthread_mutex_lock(&j->lock);
    int ready = j->state == WEB_FINISHED && j->kind == WEB_CALIBRATION && j->done_seen &&
                j->calib_choice[0] == '\0';
    if (ready) /* taken now: a second click finds it chosen */
        snprintf(j->calib_choice, sizeof(j->calib_choice), "%s", use ? "using" : "kept");
    snprintf(dir, sizeof(dir), "%s", j->dir);
    snprintf(file, sizeof(file), "%s", j->calib_file);
    snprintf(profile, sizeof(profile), "%s", j->profile);
    pthread_mutex_unlock(&j->lock);
    if (!ready)
        return api_send_error(conn, 409, "no finished calibration waits for a choice");
    cJSON *o = cJSON_CreateObject();
    if (!use)
        return api_send_json(conn, 200, o);
    struct app_config cfg;
    char fresh[WEB_PATH + 32], kept[WEB_PATH + 40], err[WEB_PATH + 256];
    snprintf(fresh, sizeof(fresh), "%s/" WEB_CALIB_FILE, dir);
    int rc = profile_config(s, profile, &cfg, err, sizeof(err)) != NULL ? 0 : -EINVAL;
    if (rc == 0)
        rc = install(fresh, file, cfg.light_count, kept, sizeof(kept), err, sizeof(err));
    pthread_mutex_lock(&j->lock);
    snprintf(j->calib_choice, sizeof(j->calib_choice), "%s", rc == 0 ? "used" : "");
    pthread_mutex_unlock(&j->lock);
    if (rc != 0) {
        cJSON_Delete(o);
        fprintf(stderr, "scanner-web: %s\n", err);
        return api_send_error(conn, 500, err);
    }
    fprintf(stderr, "scanner-web: calibration %s now in use as %s%s%s\n", fresh, file,
            kept[0] ? "; the old one is kept as " : "", kept);
    cJSON_AddStringToObject(o, "file", file);
    cJSON_AddStringToObject(o, "kept", kept);
    return api_send_json(conn, 200, o);
}

/* GET /api/calibration/live.png: the last picture the calibration took, its corners drawn. */
static int send_live(struct mg_connection *conn, struct web_server *s)
{
    struct web_job *j = &s->job;
    char path[WEB_PATH + 32];
    pthread_mutex_lock(&j->lock);
    int have = j->state != WEB_IDLE && j->kind == WEB_CALIBRATION;
    snprintf(path, sizeof(path), "%s/" WEB_CALIB_CAPTURES "/live.png", j->dir);
    pthread_mutex_unlock(&j->lock);
    /* the scanner writes a plain file there: a link put in its place leads nowhere */
    FILE *f = have ? file_open_regular_nolink(path, "rb") : NULL;
    char *png = f != NULL ? malloc(CAL_MAX_FILE) : NULL;
    size_t n = png != NULL ? fread(png, 1, CAL_MAX_FILE, f) : 0;
    if (f != NULL)
        fclose(f);
    if (n == 0 || n == CAL_MAX_FILE) {
        free(png);
        return api_send_error(conn, 404, "no picture yet");
    }
    api_send_png(conn, png, n);
    free(png);
    return 200;
}

int calibration_handle(struct mg_connection *conn, struct web_server *s, const char *method,
                       const char *rest)
{
    int is_get = strcmp(method, "GET") == 0, is_post = strcmp(method, "POST") == 0;
    if (rest[0] == '\0' && is_get)
        return get_state(conn, s);
    if (strcmp(rest, "/live.png") == 0 && is_get)
        return send_live(conn, s);
    int known = rest[0] == '\0' || strcmp(rest, "/verify") == 0 || strcmp(rest, "/answer") == 0 ||
                strcmp(rest, "/stop") == 0 || strcmp(rest, "/use") == 0 ||
                strcmp(rest, "/keep") == 0;
    if (!known || !is_post)
        return api_send_error(conn, known ? 405 : 404, "no such request (docs/api.md)");
    if (!api_may_use_rig(s, conn)) /* a page of another site must not move the rig */
        return api_refuse_without_key(conn);
    if (rest[0] == '\0' || strcmp(rest, "/verify") == 0)
        return start(conn, s, rest[0] != '\0');
    if (strcmp(rest, "/answer") == 0)
        return answer(conn, s);
    if (strcmp(rest, "/stop") == 0) {
        enum web_kind kind;
        char id[64];
        int rc = running(s, &kind, id, sizeof(id));
        return rc == 0 && jobs_stop(s, kind, id) == 0
                   ? api_send_json(conn, 200, cJSON_CreateObject())
                   : api_send_error(conn, 409, "no calibration is running");
    }
    return choose(conn, s, strcmp(rest, "/use") == 0);
}
