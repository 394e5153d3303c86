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

/** The value of an INI_LIST key: how many numbers were given, and them. */
struct ini_list {
    unsigned count;
    double value[INI_LIST_MAX];
};

struct ini_key {
    const char *section;
    const char *name;
    enum ini_type type;
    size_t offset;       /**< into the target struct */
    size_t size;         /**< INI_STR: buffer size; INI_VEC: number of doubles; INI_LIST: most */
    double min, max;     /**< numeric range (each element of a vector) */
    int max_is_limit;    /**< max is a compiled buffer limit: say so in the error */
    const char *def;     /**< default, as it would be written in the file; NULL = required */
    const char *choices; /**< INI_ENUM: "a|b|c" */
    const char *doc;     /**< one sentence for docs/config.md */
};

#define INI_MAX_KEYS 192

/** Parse @p path against @p keys into @p target. Unknown sections and keys, duplicates, bad
 *  values and missing required keys are errors naming file, line and key.
 *  @retval 0 ok @retval -ENOENT no file @retval -EINVAL bad content (message in @p err) */
int ini_schema_load(const struct ini_key *keys, size_t key_count, void *target, const char *path,
                    char *err, size_t err_len);

/** Markdown documentation of a table: a section heading and a table per section. */
void ini_schema_print_doc(const struct ini_key *keys, size_t key_count, FILE *out);

#endif
