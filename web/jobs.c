/* The rig's users, as child processes of the web server: a scan or a resume (`scanner ... --json`,
 * whose event lines a reader thread turns into the job's state), a selftest, a snapshot. The
 * scanner program keeps the rig safe on every exit path of its own; the server only asks it to
 * stop (SIGTERM) and never kills it harder. */
#define _GNU_SOURCE
#include "web.h"

#include "file_posix.h"
#include "scan_dir.h"
#include "scan_events.h"

#include <cJSON.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

const char *web_state_name(enum web_state state)
{
    static const char *const names[] = {"idle", "running", "finished", "failed", "stopped"};
    return names[state];
}

int web_name_ok(const char *name)
{
    if (name[0] == '\0' || name[0] == '.' || strlen(name) > 128)
        return 0;
    for (const char *c = name; *c != '\0'; c++)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
              *c == '_' || *c == '-' || *c == '.'))
            return 0;
    return 1;
}

/* The child is asked to stop with SIGTERM, the scanner's orderly shutdown. */
pid_t web_spawn(const char *const *args, int *fd_in, int *fd_out, int *fd_err)
{
    int out[2], err[2] = {-1, -1}, in[2] = {-1, -1};
    if (pipe2(out, O_CLOEXEC) != 0)
        return -errno;
    if ((fd_err != NULL && pipe2(err, O_CLOEXEC) != 0) ||
        (fd_in != NULL && pipe2(in, O_CLOEXEC) != 0)) {
        int e = errno;
        close(out[0]);
        close(out[1]);
        for (int k = 0; k < 2; k++) {
            if (err[k] >= 0)
                close(err[k]);
        }
        return -e;
    }
    pid_t pid = fork();
    if (pid == 0) {
        sigset_t none; /* the server's threads block its stop signals; the child must not */
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, NULL);
        signal(SIGPIPE, SIG_DFL);
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        int null = open("/dev/null", O_RDWR);
        dup2(fd_in != NULL ? in[0] : null, STDIN_FILENO);
        dup2(out[1], STDOUT_FILENO);
        dup2(fd_err != NULL ? err[1] : null, STDERR_FILENO);
        execv(args[0], (char *const *)args);
        _exit(127);
    }
    int e = errno;
    close(out[1]);
    if (err[1] >= 0)
        close(err[1]);
    if (in[0] >= 0)
        close(in[0]);
    if (pid < 0) {
        close(out[0]);
        if (err[0] >= 0)
            close(err[0]);
        if (in[1] >= 0)
            close(in[1]);
        return -e;
    }
    if (fd_in != NULL)
        *fd_in = in[1];
    *fd_out = out[0];
    if (fd_err != NULL)
        *fd_err = err[0];
    return pid;
}

/* The question @p ev asks (its "answers"; a second pass's place_object takes "continue"), kept
 * as the only answers the page may send (none: it asks nothing). */
static void take_question(struct web_job *j, const cJSON *ev, const char *name)
{
    const cJSON *answers = cJSON_GetObjectItemCaseSensitive(ev, "answers"), *a;
    j->answers = 0;
    if (strcmp(name, EV_PLACE_OBJECT) == 0)
        snprintf(j->answer[j->answers++], WEB_MAX_ANSWER, "continue");
    if (!cJSON_IsArray(answers))
        return;
    cJSON_ArrayForEach(a, answers)
    {
        if (j->answers < WEB_MAX_ANSWERS && cJSON_IsString(a) &&
            strlen(a->valuestring) < WEB_MAX_ANSWER)
            snprintf(j->answer[j->answers++], WEB_MAX_ANSWER, "%s", a->valuestring);
    }
}

/* A calibration's event kept for the page: the live picture's, the result, or in the log. */
static void keep_calibration_event(struct web_job *j, const char *name, const char *line)
{
    size_t len = strlen(line);
    if (strcmp(name, "calib_live") == 0 || strcmp(name, "calib_capture") == 0)
        j->calib_pictures++;
    if (strcmp(name, "calib_live") == 0)
        snprintf(j->calib_live, sizeof(j->calib_live), "%s",
                 len < sizeof(j->calib_live) ? line : "");
    else if (strcmp(name, "calibration") == 0 || strcmp(name, "calib_verify") == 0)
        snprintf(j->calib_result, sizeof(j->calib_result), "%s", line);
    else if (j->calib_log_len + len + 2 <= sizeof(j->calib_log)) { /* beyond: left out */
        memcpy(j->calib_log + j->calib_log_len, line, len);
        j->calib_log_len += len;
        j->calib_log[j->calib_log_len++] = '\n';
        j->calib_log[j->calib_log_len] = '\0';
    }
}

/* One event line of `scanner --json` (docs/api.md lists them) into the job's state. */
static void on_event(struct web_job *j, const char *line)
{
    cJSON *ev = cJSON_Parse(line);
    const cJSON *event = cJSON_GetObjectItemCaseSensitive(ev, "event");
    if (!cJSON_IsString(event)) {
        cJSON_Delete(ev);
        return;
    }
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(ev, "views");
    const cJSON *done = cJSON_GetObjectItemCaseSensitive(ev, "views_done");
    const cJSON *elapsed = cJSON_GetObjectItemCaseSensitive(ev, "elapsed_s");
    const cJSON *left = cJSON_GetObjectItemCaseSensitive(ev, "left_s");
    const cJSON *detail = cJSON_GetObjectItemCaseSensitive(ev, "detail");
    const cJSON *written = cJSON_GetObjectItemCaseSensitive(ev, "written");
    const char *e = event->valuestring;
    pthread_mutex_lock(&j->lock);
    if (j->kind != WEB_SCAN)
        keep_calibration_event(j, e, line);
    if (strcmp(e, "calib_live") == 0) { /* a picture while the question waits: no new stage */
        j->seq++;
        pthread_cond_broadcast(&j->changed);
        pthread_mutex_unlock(&j->lock);
        cJSON_Delete(ev);
        return;
    }
    snprintf(j->stage, sizeof(j->stage), "%s", e);
    take_question(j, ev, e);
    j->answered = 0; /* a new event: a new question, if it is one */
    if (cJSON_IsNumber(views))
        j->views_total = (unsigned)views->valuedouble;
    /* Views taken count when one is saved (its files are there: the page asks for its
     * thumbnails), decoded again, or fused; the fusion counts from 0 again: they only grow. */
    if (cJSON_IsNumber(done) &&
        (strcmp(e, EV_SAVED) == 0 || strcmp(e, EV_DECODED) == 0 || strcmp(e, EV_FUSED) == 0)) {
        j->step_done = (unsigned)done->valuedouble;
        if (j->step_done > j->views_done)
            j->views_done = j->step_done;
    }
    if (cJSON_IsNumber(elapsed))
        j->elapsed_s = elapsed->valuedouble;
    if (cJSON_IsNumber(left))
        j->left_s = left->valuedouble;
    if (cJSON_IsString(detail))
        snprintf(j->detail, sizeof(j->detail), "%s", detail->valuestring);
    if (strcmp(e, EV_SCAN_DONE) == 0 || strcmp(e, EV_PROCESS_DONE) == 0 ||
        (strcmp(e, "calibration") == 0 && cJSON_IsTrue(written)) || strcmp(e, "calib_verify") == 0)
        j->done_seen = 1;
    j->seq++;
    pthread_cond_broadcast(&j->changed);
    pthread_mutex_unlock(&j->lock);
    cJSON_Delete(ev);
}

/* The scanner's messages: the first error is the cause (each fault is said once, by the layer
 * that met it), its warnings are for the page too (a model cut by the volume must not pass for
 * the object); the rest stays in the server's log. */
static void on_message(struct web_job *j, const char *line)
{
    static const char prefix[] = "scanner: error: ", warn[] = "scanner: warning: ";
    fprintf(stderr, "%s\n", line);
    pthread_mutex_lock(&j->lock);
    if (j->error[0] == '\0' && strncmp(line, prefix, sizeof(prefix) - 1) == 0)
        snprintf(j->error, sizeof(j->error), "%s", line + sizeof(prefix) - 1);
    if (strncmp(line, warn, sizeof(warn) - 1) == 0 && j->warning_count < UINT_MAX) {
        if (j->warning_count < WEB_MAX_WARNINGS)
            snprintf(j->warnings[j->warning_count], WEB_WARNING_LEN, "%s", line + sizeof(warn) - 1);
        j->warning_count++;
        j->seq++;
        pthread_cond_broadcast(&j->changed);
    }
    pthread_mutex_unlock(&j->lock);
}

struct line_buf {
    char text[WEB_CALIB_RESULT]; /* the longest line: a calibration's result */
    size_t len;
};

/* Read what @p fd has; call @p on_line for each whole line. @retval 0 open @retval 1 at end */
static int read_lines(int fd, struct line_buf *b, struct web_job *j,
                      void (*on_line)(struct web_job *, const char *))
{
    ssize_t n = read(fd, b->text + b->len, sizeof(b->text) - 1 - b->len);
    if (n < 0 && errno == EINTR)
        return 0;
    if (n <= 0)
        return 1;
    b->len += (size_t)n;
    char *start = b->text, *nl;
    b->text[b->len] = '\0';
    while ((nl = memchr(start, '\n', b->len - (size_t)(start - b->text))) != NULL) {
        *nl = '\0';
        on_line(j, start);
        start = nl + 1;
    }
    b->len -= (size_t)(start - b->text);
    memmove(b->text, start, b->len);
    if (b->len == sizeof(b->text) - 1) /* a line longer than any the scanner writes */
        b->len = 0;
    return 0;
}

/* The wait status of child @p pid once it has ended. */
static int wait_for(pid_t pid)
{
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    return status;
}

/* Run @p args to its end, its standard output kept in @p out (up to @p out_len - 1 bytes,
 * NUL-terminated; NULL: dropped). @param status  out: its exit status, -1 after a signal
 * @retval 0 @retval -errno it could not start */
static int run_to_end(const char *const *args, char *out, size_t out_len, int *status)
{
    int fd;
    size_t used = 0;
    pid_t pid = web_spawn(args, NULL, &fd, NULL);
    for (char sink[512]; pid > 0;) {
        int keep = out != NULL && used + 1 < out_len;
        ssize_t n = read(fd, keep ? out + used : sink, keep ? out_len - 1 - used : sizeof(sink));
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        used += keep ? (size_t)n : 0;
    }
    if (out != NULL && out_len > 0)
        out[used] = '\0';
    if (pid < 0)
        return (int)pid;
    close(fd);
    int st = wait_for(pid);
    *status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    return 0;
}

/* failure.txt: the scanner's error of a scan that failed under this server, kept in its folder
 * so that the page still says why after another scan or a restart; label.txt: what a person
 * called the scan (docs/scan-format.md). */
#define FAILURE_FILE "failure.txt"
#define LABEL_FILE "label.txt"

/* @p text as file @p name of folder @p dir, whole or not at all (a temporary file, fsync,
 * rename). @retval 0 @retval -errno */
static int write_note(const char *dir, const char *name, const char *text)
{
    char path[WEB_PATH + 32], tmp[WEB_PATH + 40];
    snprintf(path, sizeof(path), "%s/%s", dir, name);
    snprintf(tmp, sizeof(tmp), "%s.tmp", path);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
    size_t len = strlen(text);
    int ok = fd >= 0 && write(fd, text, len) == (ssize_t)len && fsync(fd) == 0;
    int err = errno;
    if (fd >= 0)
        close(fd);
    if (!ok || rename(tmp, path) != 0) {
        err = ok ? errno : err;
        fprintf(stderr, "scanner-web: cannot write %s: %s\n", path, strerror(err));
        unlink(tmp);
        return -err;
    }
    return 0;
}

/* The first line of file @p name of scan @p id. @retval 0 @retval -errno (none) */
static int read_note(const struct web_server *s, const char *id, const char *name, char *text,
                     size_t len)
{
    char path[WEB_PATH + 160];
    snprintf(path, sizeof(path), "%s/%s/%s", s->scans, id, name);
    FILE *f = file_open_regular(path, "r");
    if (f == NULL)
        return -errno;
    size_t n = fread(text, 1, len - 1, f);
    text[n] = '\0';
    text[strcspn(text, "\n")] = '\0';
    fclose(f);
    return 0;
}

static void *reader_main(void *arg)
{
    struct web_server *s = arg;
    struct web_job *j = &s->job;
    struct line_buf out, err; /* 16 KB: the reader's own thread */
    out.len = err.len = 0;
    struct pollfd pf[2] = {{.fd = j->fd_out, .events = POLLIN},
                           {.fd = j->fd_err, .events = POLLIN}};
    while (pf[0].fd >= 0 || pf[1].fd >= 0) {
        if (poll(pf, 2, -1) < 0 && errno != EINTR)
            break;
        for (int k = 0; k < 2; k++)
            if (pf[k].fd >= 0 && (pf[k].revents & (POLLIN | POLLHUP | POLLERR)) &&
                read_lines(pf[k].fd, k == 0 ? &out : &err, j, k == 0 ? on_event : on_message)) {
                close(pf[k].fd);
                pf[k].fd = -1;
            }
    }
    /* waited for without reaping, and forgotten under the lock before it is reaped: a stop
     * never signals the number once it may be another process's */
    siginfo_t info;
    while (waitid(P_PID, (id_t)j->pid, &info, WEXITED | WNOWAIT) != 0 && errno == EINTR)
        ;
    pthread_mutex_lock(&j->lock);
    pid_t pid = j->pid;
    j->pid = 0;
    if (j->fd_in >= 0) /* nobody reads the answers any more */
        close(j->fd_in);
    j->fd_in = -1;
    pthread_mutex_unlock(&j->lock);
    int status = wait_for(pid);
    pthread_mutex_lock(&j->lock);
    int finished = WIFEXITED(status) && WEXITSTATUS(status) == 0 && j->done_seen;
    char dir[WEB_PATH];
    snprintf(dir, sizeof(dir), "%s", j->dir);
    pthread_mutex_unlock(&j->lock);
    /* a scan that ended early still gets its report, of what it has */
    if (!finished && j->kind == WEB_SCAN) {
        const char *args[] = {s->scanner, "report", dir, NULL};
        int ignored;
        run_to_end(args, NULL, 0, &ignored);
    }
    pthread_mutex_lock(&j->lock);
    j->state = finished ? WEB_FINISHED : j->stop_requested ? WEB_STOPPED : WEB_FAILED;
    if (j->state == WEB_FAILED && j->error[0] == '\0')
        snprintf(j->error, sizeof(j->error), "the scanner ended with %s %d",
                 WIFEXITED(status) ? "status" : "signal",
                 WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
    if (j->state == WEB_FAILED)
        write_note(dir, FAILURE_FILE, j->error);
    j->rig_busy = 0;
    j->answers = 0;
    j->seq++;
    pthread_cond_broadcast(&j->changed);
    pthread_mutex_unlock(&j->lock);
    return NULL;
}

/* The rig for a job: refused while another holds it; the last job's reader joined. */
static int claim_rig(struct web_job *j)
{
    pthread_mutex_lock(&j->lock);
    int busy = j->rig_busy;
    j->rig_busy = 1;
    pthread_mutex_unlock(&j->lock);
    if (busy)
        return -EBUSY;
    if (j->have_reader) { /* the last job's reader has ended: it freed the rig */
        pthread_join(j->reader, NULL);
        j->have_reader = 0;
    }
    return 0;
}

static void release_rig(struct web_job *j)
{
    pthread_mutex_lock(&j->lock);
    j->rig_busy = 0;
    pthread_mutex_unlock(&j->lock);
}

/* Run @p args as the rig's job (claimed) of @p kind, @p id in folder @p dir, and the thread
 * that reads its events. @retval 0 @retval -errno (@p err says what; the rig released) */
static int run_job(struct web_server *s, enum web_kind kind, const char *const *args,
                   const char *id, const char *dir, const char *profile, char *err, size_t err_len)
{
    struct web_job *j = &s->job;
    pid_t pid = web_spawn(args, &j->fd_in, &j->fd_out, &j->fd_err);
    if (pid < 0) {
        snprintf(err, err_len, "cannot start the scanner in %s: %s", dir, strerror((int)-pid));
        release_rig(j);
        return (int)pid;
    }
    pthread_mutex_lock(&j->lock);
    j->pid = pid;
    j->kind = kind;
    j->state = WEB_RUNNING;
    j->stop_requested = j->done_seen = 0;
    j->views_done = j->views_total = j->step_done = 0;
    j->answers = 0;
    j->elapsed_s = 0;
    j->left_s = -1;
    j->error[0] = j->detail[0] = '\0';
    j->warning_count = 0;
    j->calib_log[0] = j->calib_live[0] = j->calib_result[0] = j->calib_choice[0] = '\0';
    j->calib_log_len = 0;
    j->calib_pictures = 0;
    snprintf(j->stage, sizeof(j->stage), "starting");
    snprintf(j->id, sizeof(j->id), "%s", id);
    snprintf(j->dir, sizeof(j->dir), "%s", dir);
    snprintf(j->profile, sizeof(j->profile), "%s", profile);
    j->seq++;
    pthread_cond_broadcast(&j->changed);
    pthread_mutex_unlock(&j->lock);
    if (pthread_create(&j->reader, NULL, reader_main, s) == 0) {
        j->have_reader = 1;
        return 0;
    }
    /* nobody would read its events: ask it to stop (it ends on its own shutdown path) */
    kill(pid, SIGTERM);
    wait_for(pid);
    pthread_mutex_lock(&j->lock);
    j->state = WEB_FAILED;
    j->rig_busy = 0;
    pthread_mutex_unlock(&j->lock);
    snprintf(err, err_len, "cannot start a thread for the job");
    return -EAGAIN;
}

int jobs_start(struct web_server *s, const struct web_profile *p, const char *resume_id, char *id,
               size_t id_len, char *err, size_t err_len)
{
    struct web_job *j = &s->job;
    char dir[WEB_PATH];
    if (claim_rig(j) != 0) {
        snprintf(err, err_len, "the rig is busy (one scan, calibration or picture at a time)");
        return -EBUSY;
    }
    int rc = 0;
    dir[0] = '\0';
    if (resume_id != NULL) {
        snprintf(id, id_len, "%s", resume_id);
        rc = jobs_scan_dir(s, resume_id, dir, sizeof(dir));
        char failure[WEB_PATH + 32];
        snprintf(failure, sizeof(failure), "%s/" FAILURE_FILE, dir);
        if (rc == 0 && unlink(failure) != 0 && errno != ENOENT)
            rc = -errno;
    } else {
        const char *name = NULL;
        rc = scan_dir_make_new(s->scans, dir, sizeof(dir), &name);
        if (rc == 0)
            snprintf(id, id_len, "%s", name);
    }
    if (rc != 0) {
        snprintf(err, err_len, "cannot start the scanner in %s: %s", dir, strerror(-rc));
        release_rig(j);
        return rc;
    }
    const char *scan_args[] = {s->scanner, "scan", "--config", p->path,
                               "--out",    dir,    "--json",   NULL};
    const char *resume_args[] = {s->scanner, "resume", dir, "--config", p->path, "--json", NULL};
    return run_job(s, WEB_SCAN, resume_id != NULL ? resume_args : scan_args, id, dir, p->name, err,
                   err_len);
}

int jobs_start_calibration(struct web_server *s, const struct web_profile *p, int verify,
                           const char *calib_file, char *id, size_t id_len, char *err,
                           size_t err_len)
{
    struct web_job *j = &s->job;
    char dir[WEB_PATH], out[WEB_PATH + 32], captures[WEB_PATH + 32];
    if (claim_rig(j) != 0) {
        snprintf(err, err_len, "the rig is busy (one scan, calibration or picture at a time)");
        return -EBUSY;
    }
    const char *name = "verify";
    int rc = verify ? 0 : scan_dir_make_new(s->calibrations, dir, sizeof(dir), &name);
    if (rc != 0) {
        snprintf(err, err_len, "cannot make a folder in %s: %s", s->calibrations, strerror(-rc));
        release_rig(j);
        return rc;
    }
    if (verify)
        dir[0] = '\0';
    snprintf(id, id_len, "%s", name);
    snprintf(out, sizeof(out), "%s/" WEB_CALIB_FILE, dir);
    snprintf(captures, sizeof(captures), "%s/" WEB_CALIB_CAPTURES, dir);
    const char *calibrate_args[] = {s->scanner, "calibrate", "--config", p->path,  "--out",
                                    out,        "--dir",     captures,   "--json", NULL};
    const char *verify_args[] = {s->scanner, "calibrate", "verify", "--config",
                                 p->path,    "--json",    NULL};
    rc = run_job(s, verify ? WEB_VERIFY : WEB_CALIBRATION, verify ? verify_args : calibrate_args,
                 id, dir, p->name, err, err_len);
    if (rc == 0) {
        pthread_mutex_lock(&j->lock);
        snprintf(j->calib_file, sizeof(j->calib_file), "%s", calib_file);
        pthread_mutex_unlock(&j->lock);
    }
    return rc;
}

int jobs_stop(struct web_server *s, enum web_kind kind, const char *id)
{
    struct web_job *j = &s->job;
    int rc = -ESRCH;
    pthread_mutex_lock(&j->lock);
    if (j->state == WEB_RUNNING && j->kind == kind && strcmp(j->id, id) == 0 && j->pid > 0) {
        j->stop_requested = 1;
        kill(j->pid, SIGTERM);
        rc = 0;
    }
    pthread_mutex_unlock(&j->lock);
    return rc;
}

int jobs_run_tool(struct web_server *s, const char *const *args, char *out, size_t out_len,
                  int *status)
{
    struct web_job *j = &s->job;
    pthread_mutex_lock(&j->lock);
    int busy = j->rig_busy;
    j->rig_busy = 1;
    pthread_mutex_unlock(&j->lock);
    if (busy)
        return -EBUSY;
    int rc = run_to_end(args, out, out_len, status);
    pthread_mutex_lock(&j->lock);
    j->rig_busy = 0;
    pthread_mutex_unlock(&j->lock);
    return rc;
}

void jobs_shutdown(struct web_server *s)
{
    struct web_job *j = &s->job;
    pthread_mutex_lock(&j->lock);
    j->stopping = 1;
    pthread_cond_broadcast(&j->changed);
    if (j->pid > 0) {
        fprintf(stderr, "scanner-web: stopping scan %s (its finished views are kept)\n", j->id);
        j->stop_requested = 1;
        kill(j->pid, SIGTERM);
    }
    pthread_mutex_unlock(&j->lock);
    if (j->have_reader)
        pthread_join(j->reader, NULL); /* until the scanner has put the rig in its safe state */
    j->have_reader = 0;
}

int jobs_scan_dir(const struct web_server *s, const char *id, char *dir, size_t dir_len)
{
    struct stat sb;
    if (!web_name_ok(id) || (size_t)snprintf(dir, dir_len, "%s/%s", s->scans, id) >= dir_len)
        return -ENOENT;
    /* lstat: a link planted among the scans (ln -s /etc scans/evil) is no scan, and nothing is
     * served through it; the scanner's own 'latest' link is not listed twice either */
    return lstat(dir, &sb) == 0 && S_ISDIR(sb.st_mode) ? 0 : -ENOENT;
}

int jobs_describe(struct web_server *s, const char *id, enum web_state *state, unsigned *views_done,
                  unsigned *views_total, char *error, size_t error_len)
{
    struct web_job *j = &s->job;
    error[0] = '\0';
    pthread_mutex_lock(&j->lock);
    if (j->state != WEB_IDLE && j->kind == WEB_SCAN && strcmp(j->id, id) == 0) {
        *state = j->state;
        *views_done = j->views_done;
        *views_total = j->views_total;
        snprintf(error, error_len, "%s", j->error);
        pthread_mutex_unlock(&j->lock);
        return 0;
    }
    pthread_mutex_unlock(&j->lock);
    /* a scan of another time: what its folder holds (a view is complete with its view.ini) */
    char path[WEB_PATH + 64];
    if (jobs_scan_dir(s, id, path, sizeof(path)) != 0)
        return -ENOENT;
    uint32_t total;
    if (scan_dir_view_count(path, &total) != 0)
        return -ENOENT; /* not a scan */
    *views_total = total;
    *views_done = 0;
    for (unsigned v = 0; v < *views_total; v++)
        *views_done += (unsigned)scan_dir_view_complete(path, v);
    /* finished: every output written (mesh.ply alone is there before mesh.stl has failed);
     * failed: the server kept the scanner's error */
    *state = scan_dir_finished(path) ? WEB_FINISHED : WEB_STOPPED;
    if (*state == WEB_STOPPED && read_note(s, id, FAILURE_FILE, error, error_len) == 0)
        *state = WEB_FAILED;
    return 0;
}

int jobs_label(const struct web_server *s, const char *id, char *label, size_t len)
{
    int rc = read_note(s, id, LABEL_FILE, label, len);
    if (rc != 0)
        label[0] = '\0';
    return rc;
}

int jobs_set_label(struct web_server *s, const char *id, const char *label)
{
    char dir[WEB_PATH + 64];
    if (jobs_scan_dir(s, id, dir, sizeof(dir)) != 0)
        return -ENOENT;
    return write_note(dir, LABEL_FILE, label);
}

/* nftw's step: each entry removed, children first; a link is removed, never followed. */
static int remove_entry(const char *path, const struct stat *sb, int type, struct FTW *ftw)
{
    (void)sb, (void)type, (void)ftw;
    if (remove(path) != 0) {
        fprintf(stderr, "scanner-web: cannot remove %s: %s\n", path, strerror(errno));
        return -1;
    }
    return 0;
}

int jobs_delete(struct web_server *s, const char *id)
{
    char dir[WEB_PATH + 64], gone[WEB_PATH + 80];
    struct web_job *j = &s->job;
    /* Under the lock: not the scan that runs (nor one a resume is starting), and out of every
     * list at once (a name beginning with '.' is no scan's) before the slow removal. */
    pthread_mutex_lock(&j->lock);
    int running =
        (j->state == WEB_RUNNING || j->rig_busy) && j->kind == WEB_SCAN && strcmp(j->id, id) == 0;
    int rc = running ? -EBUSY : jobs_scan_dir(s, id, dir, sizeof(dir));
    if (rc == 0) {
        snprintf(gone, sizeof(gone), "%s/.deleting-%s", s->scans, id);
        rc = rename(dir, gone) == 0 ? 0 : -errno;
    }
    if (rc == 0 && j->kind == WEB_SCAN && strcmp(j->id, id) == 0) { /* its state goes too */
        j->state = WEB_IDLE;
        j->id[0] = '\0';
        j->seq++;
        pthread_cond_broadcast(&j->changed);
    }
    pthread_mutex_unlock(&j->lock);
    if (rc != 0)
        return rc;
    /* FTW_PHYS: links are not followed; FTW_MOUNT: nothing mounted inside is entered */
    return nftw(gone, remove_entry, 16, FTW_DEPTH | FTW_PHYS | FTW_MOUNT) == 0 ? 0 : -EIO;
}

int jobs_answer(struct web_server *s, enum web_kind kind, const char *id, const char *answer)
{
    struct web_job *j = &s->job;
    char line[WEB_MAX_ANSWER + 1];
    pthread_mutex_lock(&j->lock);
    int rc = j->state != WEB_RUNNING || j->kind != kind || strcmp(j->id, id) != 0 ? -ESRCH
             : j->answers == 0 || j->answered || j->fd_in < 0                     ? -EBUSY
                                                                                  : -EINVAL;
    for (unsigned k = 0; rc == -EINVAL && k < j->answers; k++)
        if (strcmp(answer, j->answer[k]) == 0)
            rc = 0;
    /* one short line into a pipe nobody else writes: whole, or the scanner has gone */
    int len = snprintf(line, sizeof(line), "%s\n", answer);
    if (rc == 0 && write(j->fd_in, line, (size_t)len) != len)
        rc = -EPIPE;
    if (rc == 0)
        j->answered = 1; /* until its next question: a second click sends nothing */
    pthread_mutex_unlock(&j->lock);
    return rc;
}
