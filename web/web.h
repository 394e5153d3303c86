/* The web interface's shared state: what it serves (configs as profiles, the scans' folder, the
 * page), who may change anything (a token off loopback), and the one scan the rig can run. */
#ifndef WEB_H
#define WEB_H

#include <limits.h>
#include <pthread.h>
#include <stddef.h>
#include <sys/types.h>

#define WEB_MAX_PROFILES 16u
#define WEB_MAX_BODY 4096 /* bytes of a request body: a profile's name is all a POST carries */
#define WEB_PATH 1024
#define WEB_MAX_LABEL 100 /* bytes of a scan's label */
#define WEB_MAX_LABEL_TEXT "100"
#define WEB_MAX_STREAMS 8 /* progress streams open at once: each holds a worker thread */
/* civetweb's workers: a connection holds one until its request is whole (10 s at most) */
#define WEB_THREADS 256

struct web_profile {
    char name[64];       /* the config file's name without .ini */
    char path[WEB_PATH]; /* the config file */
};

enum web_state { WEB_IDLE, WEB_RUNNING, WEB_FINISHED, WEB_FAILED, WEB_STOPPED };

/* What the rig's job is: a scan (or resume), a calibration, or a verification of one. */
enum web_kind { WEB_SCAN, WEB_CALIBRATION, WEB_VERIFY };

#define WEB_MAX_ANSWERS 4   /* answers a question takes */
#define WEB_MAX_ANSWER 16   /* bytes of one, with its NUL */
#define WEB_CALIB_LOG 65536 /* bytes of a calibration's events kept for the page */
/* A calibration's folder from the page: its result, and its captures (live.png among them) */
#define WEB_CALIB_FILE "calibration.ini"
#define WEB_CALIB_CAPTURES "captures"
#define WEB_CALIB_RESULT 16384 /* bytes of its result (the calibration event) */

#define WEB_MAX_WARNINGS 8
#define WEB_WARNING_LEN 400

/* The scan (or resume) the rig runs now, or ran last: a child process, `scanner scan --json`,
 * whose event lines a thread of ours reads. Every field under @c lock. */
struct web_job {
    pthread_mutex_t lock;
    pthread_cond_t changed; /* broadcast at every event (the progress streams wait on it) */
    enum web_state state;
    enum web_kind kind;
    int rig_busy; /* a scan, a snapshot or a selftest holds the rig */
    pid_t pid;    /* the scanner while it runs */
    int stop_requested;
    int have_reader;
    pthread_t reader;
    int fd_out, fd_err; /* the scanner's standard output (events) and error (messages) */
    int fd_in;          /* its standard input: the person's answer to its question, or -1 */
    int answered;       /* the question has its answer: none sent again */
    unsigned answers;   /* the question's answers (none: it asks nothing now) */
    char answer[WEB_MAX_ANSWERS][WEB_MAX_ANSWER];
    int done_seen;      /* it said scan_done or process_done */
    int stopping;       /* the server is shutting down: progress streams end */
    char id[64];        /* the scan folder's name */
    char dir[WEB_PATH]; /* the scan folder */
    char profile[64];
    unsigned views_done, views_total; /* views taken (complete), of all */
    unsigned step_done;               /* views through the current stage (taken, fused ...) */
    char stage[32];                   /* the last event: capturing, registration, meshing ... */
    char detail[512];
    double elapsed_s, left_s;
    char error[512]; /* the scanner's own error line, when it failed */
    /* its warnings (an object cut by the volume, a weak calibration ...): the first
     * WEB_MAX_WARNINGS kept, each cut at WEB_WARNING_LEN bytes; warning_count counts all */
    char warnings[WEB_MAX_WARNINGS][WEB_WARNING_LEN];
    unsigned warning_count;
    unsigned long seq; /* events so far */
    /* a calibration: its events (one JSON object a line, the live pictures' left out), the
     * last live picture's event, its result, and what the person chose to do with it */
    char calib_log[WEB_CALIB_LOG];
    size_t calib_log_len;
    char calib_live[1024];
    unsigned calib_pictures; /* pictures taken (live.png written) so far */
    char calib_result[WEB_CALIB_RESULT];
    char calib_file[WEB_PATH]; /* the profile's calibration file, which a result may replace */
    char calib_choice[16];     /* "", "used" or "kept" */
};

struct web_server {
    char scanner[WEB_PATH];      /* the scanner program the scans run in */
    char www[WEB_PATH];          /* the page */
    char scans[WEB_PATH];        /* where scan folders are made and listed */
    char calibrations[WEB_PATH]; /* where calibrations from the page keep their captures */
    struct web_profile profile[WEB_MAX_PROFILES];
    unsigned profiles;
    char token[256];  /* "" on loopback: nothing to present */
    char key[40];     /* the session key the rig's requests carry (guard.h), made at start */
    unsigned streams; /* progress streams open now (at most WEB_MAX_STREAMS), under job.lock */
    struct web_job job;
};

/* ---- jobs.c: the child processes that use the rig ---- */

/** Start `scanner scan` with @p p into a new folder under the scans' folder, or `scanner resume`
 *  of the scan @p resume_id. @param id  out: the scan's id (its folder's name)
 *  @retval 0 @retval -EBUSY the rig is in use @retval -errno (@p err says what) */
int jobs_start(struct web_server *s, const struct web_profile *p, const char *resume_id, char *id,
               size_t id_len, char *err, size_t err_len);

/** Start `scanner calibrate --json` with @p p, its captures and result in a new folder under
 *  the calibrations' folder, or (@p verify) `scanner calibrate verify --json`.
 *  @param calib_file  the profile's calibration file (which the result may replace)
 *  @param id  out: the job's id (the folder's name, or "verify")
 *  @retval 0 @retval -EBUSY the rig is in use @retval -errno (@p err says what) */
int jobs_start_calibration(struct web_server *s, const struct web_profile *p, int verify,
                           const char *calib_file, char *id, size_t id_len, char *err,
                           size_t err_len);

/** Ask the running job @p id of @p kind to stop (it stops between frames, rig safe, finished
 *  views kept). @retval 0 @retval -ESRCH not the running job */
int jobs_stop(struct web_server *s, enum web_kind kind, const char *id);

/** Run `scanner ARGS...` to its end on the rig (a selftest, a snapshot) unless a scan holds it;
 *  its standard output into @p out (at most @p out_len - 1 bytes, NUL-terminated).
 *  @param status  out: its exit status @retval 0 @retval -EBUSY @retval -errno */
int jobs_run_tool(struct web_server *s, const char *const *args, char *out, size_t out_len,
                  int *status);

/** fork and exec @p args[0] with its standard input from a pipe (@p fd_in, the end to write, or
 *  NULL: /dev/null), its standard output on a pipe (@p fd_out) and its standard error on another
 *  (@p fd_err, or NULL: /dev/null); the child is asked to stop should the server
 *  die first. @retval its pid @retval -errno */
pid_t web_spawn(const char *const *args, int *fd_in, int *fd_out, int *fd_err);

/** Stop a running scan and wait for it (its own shutdown leaves the rig safe). */
void jobs_shutdown(struct web_server *s);

/** The folder of scan @p id: a directory (not a link) directly in the scans' folder.
 *  @retval 0 @retval -ENOENT no such scan */
int jobs_scan_dir(const struct web_server *s, const char *id, char *dir, size_t dir_len);

/** The state of scan @p id: the running one's as its events say, another's from its folder.
 *  @retval 0 @retval -ENOENT no such scan */
int jobs_describe(struct web_server *s, const char *id, enum web_state *state, unsigned *views_done,
                  unsigned *views_total, char *error, size_t error_len);

/** The person's @p answer to the question of the running job @p id of @p kind (the object laid
 *  for a second pass, a calibration's step), written to its standard input, once; only an
 *  answer the question named. @retval 0 @retval -ESRCH not the running job @retval -EBUSY it
 *  asks nothing now (or has its answer) @retval -EINVAL not an answer it takes
 *  @retval -EPIPE it has gone */
int jobs_answer(struct web_server *s, enum web_kind kind, const char *id, const char *answer);

/** Delete scan @p id: its folder leaves the list at once, then is removed (links inside it are
 *  removed, not followed). @retval 0 @retval -EBUSY it is the scan that runs @retval -ENOENT
 *  no such scan @retval -errno */
int jobs_delete(struct web_server *s, const char *id);

/** What a person called scan @p id ("" when nothing). @retval 0 @retval -errno no label */
int jobs_label(const struct web_server *s, const char *id, char *label, size_t len);

/** Call scan @p id @p label (checked by the caller), kept in its folder.
 *  @retval 0 @retval -ENOENT no such scan @retval -errno */
int jobs_set_label(struct web_server *s, const char *id, const char *label);

const char *web_state_name(enum web_state state);

/** @retval 1 when @p name is one path component of letters, digits, '_', '-' and '.', not
 *  beginning with '.' (a scan id, a file name): nothing that could leave a folder. */
int web_name_ok(const char *name);

#endif
