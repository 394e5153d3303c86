/* scanner calibrate import --opencv: captures made with OpenCV's structured_light
 * GrayCodePattern (one folder per board pose, its images in the order OpenCV generates them:
 * each column bit, most significant first, then its inverse, then the row bits the same way,
 * then white and black, as its samples save them) rewritten as a calibration directory
 * (docs/calibration.md), which `scanner calibrate --from` computes from. OpenCV's sequence is the
 * scanner's own but for where white and black stand (checked against GrayCodePattern::generate
 * for a 16 x 8 projector: pattern 0 lights columns 8 .. 15, pattern 1 the others, pattern 8 rows
 * 4 .. 7), so the frames are copied, not decoded. A setup step: it allocates. */
#define _POSIX_C_SOURCE 200809L
#include "calib_priv.h"

#include "file_posix.h"
#include "gray.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define IMPORT_MAX_NAME 256           /* a pose folder's or an image's name */
#define IMPORT_MAX_FILES 1024         /* entries of one folder looked at */
#define IMPORT_MAX_BYTES (256u << 20) /* one image */

/* Names compared as people number them: "image10" after "image9". */
static int natural_order(const void *pa, const void *pb)
{
    const char *a = *(const char *const *)pa, *b = *(const char *const *)pb;
    while (*a && *b) {
        if (isdigit((unsigned char)*a) && isdigit((unsigned char)*b)) {
            unsigned long long x = strtoull(a, (char **)&a, 10), y = strtoull(b, (char **)&b, 10);
            if (x != y)
                return x < y ? -1 : 1;
            continue;
        }
        if (*a != *b)
            return (unsigned char)*a < (unsigned char)*b ? -1 : 1;
        a++, b++;
    }
    return (unsigned char)*a - (unsigned char)*b;
}

static int has_suffix(const char *name, const char *suffix)
{
    size_t n = strlen(name), k = strlen(suffix);
    return n > k && strcmp(name + n - k, suffix) == 0;
}

/* The entries of @p dir that are folders (@p folders) or PNG files, naturally ordered, into
 * @p names (each malloc'd; the caller frees them). @retval count @retval -errno (said) */
static int list_entries(const char *dir, int folders, char **names, int max)
{
    DIR *d = opendir(dir);
    if (d == NULL) {
        int e = errno;
        fprintf(stderr, "scanner: error: %s: %s\n", dir, strerror(e));
        return -e;
    }
    int n = 0;
    struct dirent *de;
    while ((de = readdir(d)) != NULL && n < max) {
        char path[2 * IMPORT_MAX_NAME + 2];
        struct stat sb;
        if (de->d_name[0] == '.' || strlen(de->d_name) >= IMPORT_MAX_NAME)
            continue;
        snprintf(path, sizeof(path), "%s/%s", dir, de->d_name);
        if (lstat(path, &sb) != 0) /* a link is not followed: no loops, nothing outside */
            continue;
        if (folders ? !S_ISDIR(sb.st_mode)
                    : !(S_ISREG(sb.st_mode) && has_suffix(de->d_name, ".png")))
            continue;
        names[n] = strdup(de->d_name);
        if (names[n] == NULL)
            break;
        n++;
    }
    closedir(d);
    qsort(names, (size_t)n, sizeof(names[0]), natural_order);
    return n;
}

static void free_names(char **names, int n)
{
    for (int i = 0; i < n; i++)
        free(names[i]);
}

/* Copy the regular file @p from to @p to, durably (hal_storage_write_file: temporary, fsync,
 * rename). @retval 0 @retval -errno (said) */
static int copy_file(const struct hal_storage *st, const char *from, const char *to)
{
    FILE *f = file_open_regular(from, "rb");
    if (f == NULL) {
        int e = errno;
        fprintf(stderr, "scanner: error: %s: %s\n", from, strerror(e));
        return -e;
    }
    int rc = 0;
    char *buf = NULL;
    long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (size < 0 || (unsigned long)size > IMPORT_MAX_BYTES) {
        fprintf(stderr, "scanner: error: %s: not an image this size\n", from);
        rc = -EFBIG;
        goto out_close;
    }
    buf = malloc((size_t)size + 1);
    rewind(f);
    if (buf == NULL || fread(buf, 1, (size_t)size, f) != (size_t)size) {
        fprintf(stderr, "scanner: error: cannot read %s\n", from);
        rc = buf == NULL ? -ENOMEM : -EIO;
        goto out_free;
    }
    rc = hal_storage_write_file(st, to, buf, (size_t)size);
    if (rc != 0)
        fprintf(stderr, "scanner: error: cannot write %s: %s\n", to, strerror(-rc));
out_free:
    free(buf);
out_close:
    fclose(f);
    return rc;
}

/* One pose folder @p pose (its @p count images) as view @p view of @p dst, or with @p dst NULL
 * only its images counted. @retval 0 @retval -errno (said) */
static int import_pose(const struct hal_storage *st, const char *pose, uint32_t count,
                       const char *dst, uint32_t view)
{
    char *names[IMPORT_MAX_FILES];
    int n = list_entries(pose, 0, names, IMPORT_MAX_FILES);
    if (n < 0)
        return n;
    int rc = 0;
    if ((uint32_t)n != count) {
        fprintf(stderr,
                "scanner: error: %s: %d PNG images, but OpenCV's GrayCodePattern for this "
                "projector makes %u (each column and row bit and its inverse, then white and "
                "black): another projector size in [calibrate] projector_width/height, or "
                "images missing?\n",
                pose, n, (unsigned)count);
        rc = -EINVAL;
        goto out_free;
    }
    if (dst == NULL)
        goto out_free;
    char dir[HAL_MAX_PATH + 16];
    snprintf(dir, sizeof(dir), "%s/view_%03u", dst, (unsigned)view);
    if (mkdir(dir, 0755) != 0) {
        rc = -errno;
        fprintf(stderr, "scanner: error: cannot make %s: %s\n", dir, strerror(-rc));
        goto out_free;
    }
    for (uint32_t i = 0; i < count && rc == 0; i++) {
        /* the scanner's frame i: white, black, then the patterns as OpenCV orders them */
        uint32_t theirs = i == GRAY_PATTERN_WHITE   ? count - 2
                          : i == GRAY_PATTERN_BLACK ? count - 1
                                                    : i - GRAY_PATTERN_FIRST_BIT;
        char from[HAL_MAX_PATH + 2 * IMPORT_MAX_NAME + 4], to[HAL_MAX_PATH + 48];
        snprintf(from, sizeof(from), "%s/%s", pose, names[theirs]);
        snprintf(to, sizeof(to), "%s/frame_%02u.png", dir, (unsigned)i);
        rc = copy_file(st, from, to);
    }
out_free:
    free_names(names, n);
    return rc;
}

int calibrate_import_opencv(const struct hal_storage *st, const struct app_config *cfg,
                            const char *src, const char *dst)
{
    struct scan_calib calib;
    char err[512];
    int rc = calib_load(&calib, cfg->calibration_file, cfg->light_count, err, sizeof(err));
    if (rc == -ENOENT) {
        calibrate_guess(cfg, &calib); /* the projector's size from [calibrate] */
        rc = 0;
    } else if (rc != 0) {
        fprintf(stderr, "scanner: error: %s\n", err);
        return rc;
    }
    struct gray_layout layout;
    gray_layout_for(calib.proj_width, calib.proj_height, 1, &layout);
    uint32_t count = gray_layout_count(&layout);
    if (strlen(src) + IMPORT_MAX_NAME + 2 >= HAL_MAX_PATH || strlen(dst) + 32 >= HAL_MAX_PATH) {
        fprintf(stderr, "scanner: error: a path is longer than %d characters\n", HAL_MAX_PATH);
        return -ENAMETOOLONG;
    }
    char *poses[IMPORT_MAX_FILES];
    int n = list_entries(src, 1, poses, IMPORT_MAX_FILES);
    if (n <= 0) {
        if (n == 0)
            fprintf(stderr, "scanner: error: %s holds no folder of images (one a board pose)\n",
                    src);
        return n == 0 ? -ENOENT : n;
    }
    /* Two passes: every pose's images counted before anything is written, then copied into a
     * new folder (nothing of another calibration overwritten). */
    for (int pass = 0; pass < 2 && rc == 0; pass++) {
        if (pass == 1 && mkdir(dst, 0755) != 0) {
            rc = -errno;
            fprintf(stderr, "scanner: error: cannot make %s: %s%s\n", dst, strerror(-rc),
                    rc == -EEXIST ? " (give a new folder)" : "");
        }
        for (int i = 0; i < n && rc == 0; i++) {
            char pose[HAL_MAX_PATH + IMPORT_MAX_NAME + 2];
            snprintf(pose, sizeof(pose), "%s/%s", src, poses[i]);
            rc = import_pose(st, pose, count, pass == 1 ? dst : NULL, (uint32_t)i);
            if (rc == 0 && pass == 1)
                printf("%s -> %s/view_%03d\n", pose, dst, i);
        }
    }
    free_names(poses, n);
    if (rc == 0)
        printf("imported %d board poses into %s: 'scanner calibrate --config F --from %s --out "
               "FILE' computes the calibration\n",
               n, dst, dst);
    return rc < 0 ? rc : 0;
}
