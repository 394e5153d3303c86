/* inih-based parser driven by a key table; tracks line numbers through a counting reader. */
#define _POSIX_C_SOURCE 200809L
#include "ini_schema.h"

#include "file_posix.h"

#include "hal_gpio.h"

#include <errno.h>
#include <fcntl.h>
#include <ini.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* A config or calibration is a few kilobytes; anything far larger is not one. */
#define INI_MAX_FILE_BYTES (1u << 20)

struct parse_state {
    const struct ini_key *keys;
    size_t key_count;
    void *target;
    const char *path;
    FILE *file;
    int line;                    /* line inih is handling now */
    int seen_line[INI_MAX_KEYS]; /* 0 = not seen */
    char *err;
    size_t err_len;
    int failed;
};

/* inih reads one line per call: counting here gives the line of the key being handled. A line
 * longer than inih's buffer would come in pieces, the tail read as a line of its own (a comment's
 * tail taken for a key): it is refused instead. */
static char *counting_reader(char *str, int num, void *stream)
{
    struct parse_state *st = stream;
    char *r = fgets(str, num, st->file);
    if (r == NULL || st->failed)
        return NULL;
    st->line++;
    size_t n = strlen(r);
    if (n + 1 == (size_t)num && r[n - 1] != '\n' && !feof(st->file)) {
        snprintf(st->err, st->err_len, "%s:%d: line longer than %d characters", st->path, st->line,
                 num - 2);
        st->failed = 1;
        return NULL;
    }
    return r;
}

/* Open @p path for reading if it is a regular file of a sensible size (a device such as
 * /dev/zero, a FIFO or a directory is not a config). @retval 0 @retval -errno, said in @p err */
static int open_regular(const char *path, FILE **out, char *err, size_t err_len)
{
    int fd = file_open_regular_fd(path);
    struct stat st;
    int rc = fd < 0 ? fd : fstat(fd, &st) != 0 ? -errno : 0;
    if (rc == -EISDIR || rc == -EINVAL) {
        snprintf(err, err_len, "%s: not a regular file (%s)", path,
                 rc == -EISDIR ? "a directory" : "a device, pipe or socket");
    } else if (rc != 0) {
        snprintf(err, err_len, "%s: cannot open: %s", path, strerror(-rc));
    } else if (st.st_size > (off_t)INI_MAX_FILE_BYTES) {
        rc = -EFBIG;
        snprintf(err, err_len,
                 "%s: %lld bytes, too large for a config or calibration (at most "
                 "%u)",
                 path, (long long)st.st_size, INI_MAX_FILE_BYTES);
    } else if ((*out = fdopen(fd, "r")) == NULL) {
        rc = -errno;
        snprintf(err, err_len, "%s: cannot open: %s", path, strerror(-rc));
    }
    if (rc != 0 && fd >= 0)
        close(fd);
    return rc;
}

static int parse_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    *out = strtod(s, &end);
    while (*end == ' ' || *end == '\t')
        end++;
    return (end != s && *end == '\0' && errno == 0 && isfinite(*out)) ? 0 : -1;
}

static int choice_ok(const char *choices, const char *value)
{
    size_t len = strlen(value);
    for (const char *p = choices; *p != '\0';) {
        const char *bar = strchr(p, '|');
        size_t n = bar ? (size_t)(bar - p) : strlen(p);
        if (n == len && strncmp(p, value, n) == 0)
            return 1;
        p += n + (bar ? 1 : 0);
    }
    return 0;
}

static void format_where(char *err, size_t len, const char *path, int line, const struct ini_key *k,
                         const char *what)
{
    if (line > 0)
        snprintf(err, len, "%s:%d: [%s] %s: %s", path, line, k->section, k->name, what);
    else
        snprintf(err, len, "%s: [%s] %s: %s", path, k->section, k->name, what);
}

static int range_error(const struct ini_key *k, double v, char *msg, size_t len)
{
    if (v >= k->min && v <= k->max)
        return 0;
    if (k->limit != NULL && k->limit[0] != '\0' && v > k->max)
        snprintf(msg, len, "%g exceeds the compiled limit %g: %s", v, k->max, k->limit);
    else if (k->limit != NULL && v > k->max)
        snprintf(msg, len, "%g exceeds the compiled limit %g (see hal/include/hal_limits.h)", v,
                 k->max);
    else
        snprintf(msg, len, "%g is out of range %g..%g", v, k->min, k->max);
    return -1;
}

/* A GPIO line: an offset in range, or a name of letters, digits, '_' and '-'. */
static int set_line(const struct ini_key *k, struct hal_gpio_line_ref *ref, const char *value,
                    char *msg, size_t len)
{
    double v;
    memset(ref, 0, sizeof(*ref));
    if (parse_double(value, &v) == 0) {
        if (v != floor(v)) {
            snprintf(msg, len, "'%s' is not a line offset", value);
            return -1;
        }
        if (range_error(k, v, msg, len))
            return -1;
        ref->offset = (int32_t)v;
        return 0;
    }
    size_t n = strlen(value);
    if (n == 0 || n >= sizeof(ref->name) ||
        strspn(value, "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
                      "abcdefghijklmnopqrstuvwxyz"
                      "0123456789_-") != n) {
        snprintf(msg, len, "'%s' is neither a line offset nor a line name", value);
        return -1;
    }
    ref->offset = -1;
    memcpy(ref->name, value, n + 1);
    return 0;
}

/* Store @p value for key @p k, or write what is wrong into @p msg. */
static int set_value(const struct ini_key *k, void *target, const char *value, char *msg,
                     size_t len)
{
    char *dst = (char *)target + k->offset;
    double v;
    switch (k->type) {
    case INI_U32:
    case INI_I32:
        if (parse_double(value, &v) != 0 || v != floor(v)) {
            snprintf(msg, len, "'%s' is not a whole number", value);
            return -1;
        }
        if (range_error(k, v, msg, len))
            return -1;
        if (k->type == INI_U32)
            *(uint32_t *)(void *)dst = (uint32_t)v;
        else
            *(int32_t *)(void *)dst = (int32_t)v;
        return 0;
    case INI_LINE:
        return set_line(k, (struct hal_gpio_line_ref *)(void *)dst, value, msg, len);
    case INI_F64:
        if (parse_double(value, &v) != 0) {
            snprintf(msg, len, "'%s' is not a number", value);
            return -1;
        }
        if (range_error(k, v, msg, len))
            return -1;
        *(double *)(void *)dst = v;
        return 0;
    case INI_ENUM:
        if (!choice_ok(k->choices, value)) {
            snprintf(msg, len, "'%s' is not one of %s", value, k->choices);
            return -1;
        }
        /* A valid choice is stored as a string. */
        __attribute__((fallthrough));
    case INI_STR:
        if (strlen(value) >= k->size) {
            snprintf(msg, len, "value longer than %zu characters", k->size - 1);
            return -1;
        }
        memcpy(dst, value, strlen(value) + 1);
        return 0;
    case INI_LIST: {
        struct ini_list *list = (struct ini_list *)(void *)dst;
        char buf[512];
        snprintf(buf, sizeof(buf), "%s", value);
        list->count = 0;
        list->given = 1; /* ini_schema_load_with takes it back for a default */
        for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok != NULL;
             tok = strtok_r(NULL, ",", &save)) {
            while (*tok == ' ' || *tok == '\t')
                tok++;
            if (list->count == k->size || list->count == INI_LIST_MAX ||
                parse_double(tok, &v) != 0) {
                snprintf(msg, len, "'%s' is not a list of at most %zu numbers", value, k->size);
                return -1;
            }
            if (range_error(k, v, msg, len))
                return -1;
            list->value[list->count++] = v;
        }
        return 0;
    }
    case INI_VEC: {
        char buf[512];
        snprintf(buf, sizeof(buf), "%s", value);
        size_t n = 0;
        for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok != NULL;
             tok = strtok_r(NULL, ",", &save)) {
            while (*tok == ' ' || *tok == '\t')
                tok++;
            if (n == k->size || parse_double(tok, &v) != 0 || range_error(k, v, msg, len)) {
                if (n == k->size || parse_double(tok, &v) != 0)
                    snprintf(msg, len, "'%s' is not a list of %zu numbers", value, k->size);
                return -1;
            }
            ((double *)(void *)dst)[n++] = v;
        }
        if (n != k->size) {
            snprintf(msg, len, "'%s' is not a list of %zu numbers", value, k->size);
            return -1;
        }
        return 0;
    }
    }
    return -1;
}

static int handler(void *user, const char *section, const char *name, const char *value)
{
    struct parse_state *st = user;
    char msg[512];
    if (st->failed) /* report the first error, not the last */
        return 0;
    if (strcmp(section, "color") == 0) /* both spellings of the one section */
        section = "colour";
    for (size_t i = 0; i < st->key_count; i++) {
        const struct ini_key *k = &st->keys[i];
        if (strcmp(k->section, section) != 0 || strcmp(k->name, name) != 0)
            continue;
        if (st->seen_line[i] != 0) {
            snprintf(msg, sizeof(msg), "set twice (first on line %d)", st->seen_line[i]);
            format_where(st->err, st->err_len, st->path, st->line, k, msg);
            st->failed = 1;
            return 0;
        }
        if (set_value(k, st->target, value, msg, sizeof(msg)) != 0) {
            format_where(st->err, st->err_len, st->path, st->line, k, msg);
            st->failed = 1;
            return 0;
        }
        st->seen_line[i] = st->line;
        return 1;
    }
    int section_known = 0;
    for (size_t i = 0; i < st->key_count; i++)
        section_known |= strcmp(st->keys[i].section, section) == 0;
    if (section_known)
        snprintf(st->err, st->err_len, "%s:%d: [%s] %s: unknown key", st->path, st->line, section,
                 name);
    else
        snprintf(st->err, st->err_len, "%s:%d: [%s] %s: unknown section '%s'", st->path, st->line,
                 section, name, section);
    st->failed = 1;
    return 0;
}

int ini_schema_load(const struct ini_key *keys, size_t key_count, void *target, const char *path,
                    char *err, size_t err_len)
{
    return ini_schema_load_with(keys, key_count, target, path, NULL, 0, err, err_len);
}

/* The fallback for @p k among @p fallbacks, or its own default (NULL: required). */
static const char *missing_value(const struct ini_key *k, const struct ini_fallback *fallbacks,
                                 size_t fallback_count)
{
    for (size_t f = 0; f < fallback_count; f++)
        if (strcmp(fallbacks[f].section, k->section) == 0 && strcmp(fallbacks[f].key, k->name) == 0)
            return fallbacks[f].value;
    return k->def;
}

int ini_schema_load_with(const struct ini_key *keys, size_t key_count, void *target,
                         const char *path, const struct ini_fallback *fallbacks,
                         size_t fallback_count, char *err, size_t err_len)
{
    struct parse_state st = {.keys = keys,
                             .key_count = key_count,
                             .target = target,
                             .path = path,
                             .err = err,
                             .err_len = err_len};
    if (key_count > INI_MAX_KEYS) {
        snprintf(err, err_len, "internal: schema has %zu keys, more than %d", key_count,
                 INI_MAX_KEYS);
        return -EINVAL;
    }
    int rc_open = open_regular(path, &st.file, err, err_len);
    if (rc_open != 0)
        return rc_open;
    int rc = ini_parse_stream(counting_reader, &st, handler, &st);
    fclose(st.file);
    if (st.failed)
        return -EINVAL;
    if (rc != 0) { /* a syntax error inih found itself: rc is its line */
        snprintf(err, err_len, "%s:%d: syntax error (expected [section] or key = value)", path, rc);
        return -EINVAL;
    }
    for (size_t i = 0; i < key_count; i++) {
        if (st.seen_line[i] != 0)
            continue;
        char msg[512];
        const char *value = missing_value(&keys[i], fallbacks, fallback_count);
        if (value == NULL) {
            format_where(err, err_len, path, 0, &keys[i], "required key is missing");
            return -EINVAL;
        }
        if (set_value(&keys[i], target, value, msg, sizeof(msg)) != 0) {
            format_where(err, err_len, "(built-in default)", 0, &keys[i], msg);
            return -EINVAL;
        }
        if (keys[i].type == INI_LIST) /* a default is not the file's */
            ((struct ini_list *)(void *)((char *)target + keys[i].offset))->given = 0;
    }
    return 0;
}

static const char *type_name(const struct ini_key *k, char *buf, size_t len)
{
    switch (k->type) {
    case INI_U32:
        return "unsigned";
    case INI_I32:
        return "integer";
    case INI_F64:
        return "number";
    case INI_STR:
        return "text";
    case INI_ENUM: { /* "a|b" would split a Markdown table cell */
        size_t n = 0;
        for (const char *p = k->choices; *p != '\0' && n + 3 < len; p++) {
            if (*p == '|') {
                buf[n++] = ',';
                buf[n++] = ' ';
            } else {
                buf[n++] = *p;
            }
        }
        buf[n] = '\0';
        return buf;
    }
    case INI_VEC:
        return k->size == 3 ? "x, y, z" : k->size == 2 ? "x, y" : "list of numbers";
    case INI_LIST:
        snprintf(buf, len, "up to %zu numbers", k->size);
        return buf;
    case INI_LINE:
        return "offset or name";
    }
    return "?";
}

void ini_schema_print_doc(const struct ini_key *keys, size_t key_count, FILE *out)
{
    const char *section = "";
    for (size_t i = 0; i < key_count; i++) {
        const struct ini_key *k = &keys[i];
        if (strcmp(section, k->section) != 0) {
            section = k->section;
            fprintf(out,
                    "\n### [%s]\n\n| key | type | default | range | meaning |\n"
                    "|---|---|---|---|---|\n",
                    section);
        }
        char range[64] = "", type_buf[128];
        if (k->type == INI_U32 || k->type == INI_I32 || k->type == INI_F64 || k->type == INI_VEC ||
            k->type == INI_LINE || k->type == INI_LIST)
            snprintf(range, sizeof(range), "%.10g .. %.10g%s", k->min, k->max,
                     k->limit != NULL ? " (compiled limit)" : "");
        fprintf(out, "| `%s` | %s | %s | %s | %s |\n", k->name,
                type_name(k, type_buf, sizeof(type_buf)),
                k->def == NULL ? "**required**" : (k->def[0] ? k->def : "(empty)"), range, k->doc);
    }
}

/* ---- the writer ---- */

/* Append to @p buf at *@p at; past the end only counts (the caller checks once). */
__attribute__((format(printf, 4, 5))) static void put(char *buf, size_t len, size_t *at,
                                                      const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf + (*at < len ? *at : len), *at < len ? len - *at : 0, fmt, ap);
    va_end(ap);
    *at += n > 0 ? (size_t)n : 0;
}

static int put_value(const struct ini_key *k, const void *target, char *buf, size_t len, size_t *at)
{
    const char *p = (const char *)target + k->offset;
    switch (k->type) {
    case INI_U32:
        put(buf, len, at, k->fmt != NULL ? k->fmt : "%u", (unsigned)*(const uint32_t *)p);
        return 0;
    case INI_I32:
        put(buf, len, at, k->fmt != NULL ? k->fmt : "%d", (int)*(const int32_t *)p);
        return 0;
    case INI_F64:
        put(buf, len, at, k->fmt != NULL ? k->fmt : "%.12g", *(const double *)p);
        return 0;
    case INI_STR:
    case INI_ENUM: /* a choice, kept as a string */
        put(buf, len, at, "%s", p);
        return 0;
    case INI_VEC:
        for (size_t i = 0; i < k->size; i++) {
            if (i > 0)
                put(buf, len, at, ", ");
            put(buf, len, at, k->fmt != NULL ? k->fmt : "%.12g", ((const double *)p)[i]);
        }
        return 0;
    default:
        return -EINVAL;
    }
}

int ini_schema_write(const struct ini_key *keys, size_t key_count, const void *target,
                     const char *header, ini_schema_skip_fn skip, const char *section_gap,
                     char *buf, size_t len)
{
    size_t at = 0;
    if (header != NULL)
        put(buf, len, &at, "%s", header);
    const char *section = NULL;
    for (size_t i = 0; i < key_count; i++) {
        const struct ini_key *k = &keys[i];
        if (k->name == NULL || (skip != NULL && skip(k, target)))
            continue;
        if (section == NULL || strcmp(section, k->section) != 0) {
            put(buf, len, &at, "%s[%s]\n", section != NULL ? section_gap : "", k->section);
            section = k->section;
        }
        if (k->note != NULL)
            put(buf, len, &at, "; %s\n", k->note);
        put(buf, len, &at, "%s = ", k->name);
        if (put_value(k, target, buf, len, &at) != 0)
            return -EINVAL;
        put(buf, len, &at, "\n");
    }
    return at < len && at <= INT32_MAX ? (int)at : -ENOSPC;
}
