/* Table-driven INI parsing on inih: one table per file kind drives parsing, defaults, range checks,
 * error messages (file, line, key) and the generated documentation. */
#ifndef INI_SCHEMA_H
#define INI_SCHEMA_H

#include <stddef.h>
#include <stdio.h>

/* INI_LINE: a GPIO line as a whole number (offset; -1 = not wired) or a name, into a
 * struct hal_gpio_line_ref. */
/* INI_LIST: up to size numbers (at most INI_LIST_MAX), into a struct ini_list; empty: none. */
enum ini_type { INI_U32, INI_I32, INI_F64, INI_STR, INI_ENUM, INI_VEC, INI_LINE, INI_LIST };

#define INI_LIST_MAX 8

/** The value of an INI_LIST key: how many numbers were given, and them; @c given: the file set
 *  the key (empty too), not its default or a fallback (what a person chose, left to the scanner
 *  otherwise: [scan] auto_exposure). */
struct ini_list {
    unsigned count;
    unsigned given;
    double value[INI_LIST_MAX];
};

struct ini_key {
    const char *section;
    const char *name;
    enum ini_type type;
    size_t offset;   /**< into the target struct */
    size_t size;     /**< INI_STR: buffer size; INI_VEC: number of doubles; INI_LIST: most */
    double min, max; /**< numeric range (each element of a vector) */
    /** Non-NULL: max is a compiled buffer limit, said so in the error with this, what a person
     *  can do instead ("": the header that sets it is named) */
    const char *limit;
    const char *def;     /**< default, as it would be written in the file; NULL = required */
    const char *choices; /**< INI_ENUM: "a|b|c" */
    const char *doc;     /**< one sentence for docs/config.md */
    /* for the files the scanner writes as well as reads (ini_schema_write): */
    const char *fmt;  /**< a number's printf format (NULL: %u, %d, %.12g) */
    const char *note; /**< a comment line written before the key, or NULL */
};

#define INI_MAX_KEYS 192

/** Parse @p path against @p keys into @p target. Unknown sections and keys, duplicates, bad
 *  values and missing required keys are errors naming file, line and key.
 *  @retval 0 ok @retval -ENOENT no file @retval -EINVAL bad content (message in @p err) */
int ini_schema_load(const struct ini_key *keys, size_t key_count, void *target, const char *path,
                    char *err, size_t err_len);

/** A value for a key the file leaves out, taken in place of the key's default or of its being
 *  required: what a command that has no use for the key gives it (calibrating from captures on
 *  disk needs no exposure). */
struct ini_fallback {
    const char *section, *key, *value;
};

/** ini_schema_load, with @p fallbacks (@p fallback_count of them) for keys the file leaves out.
 *  @retval as ini_schema_load */
int ini_schema_load_with(const struct ini_key *keys, size_t key_count, void *target,
                         const char *path, const struct ini_fallback *fallbacks,
                         size_t fallback_count, char *err, size_t err_len);

/** Which keys ini_schema_write leaves out: @retval 1 leave @p key out of @p target's file. */
typedef int (*ini_schema_skip_fn)(const struct ini_key *key, const void *target);

/** Write @p target as the file @p keys describe (the same table the reader takes, so the two
 *  agree): @p header as it is (NULL: none), then "[section]" where the section changes, @p
 * section_gap before every section but the first, "name = value" in the table's order, numbers with
 * the key's fmt, vectors as "a, b, c". INI_U32, INI_I32, INI_F64, INI_STR, INI_ENUM and INI_VEC
 * only.
 *  @param skip  keys to leave out (NULL: none)
 *  @retval the length written @retval -ENOSPC @p buf too small @retval -EINVAL a type it cannot
 *  write */
int ini_schema_write(const struct ini_key *keys, size_t key_count, const void *target,
                     const char *header, ini_schema_skip_fn skip, const char *section_gap,
                     char *buf, size_t len);

/** Markdown documentation of a table: a section heading and a table per section. */
void ini_schema_print_doc(const struct ini_key *keys, size_t key_count, FILE *out);

#endif
