/* The calibration directory's own files: target.ini per capture, the settings kept with the
 * captures, and the board as SVG (docs/calibration.md, "The calibration directory"). */
#define _POSIX_C_SOURCE 200809L
#include "calib_priv.h"

#include "ini_schema.h"
#include "scan_dir.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

struct target_file {
    char target[16];
    uint32_t placement;
    double tilt_deg;
    int32_t angle_mdeg;
    uint32_t has_angle;
};

#define T(member) offsetof(struct target_file, member)
static const struct ini_key target_keys[] = {
    {"target", "target", INI_ENUM, T(target), sizeof(((struct target_file *)0)->target), 0, 0, 0,
     "board", "board|sphere", "what stood on the table", NULL, NULL},
    {"target", "placement", INI_U32, T(placement), 0, 0, 1000, 0, "0", NULL,
     "board placement: captures of one placement differ only by the table's angle", NULL, NULL},
    {"target", "tilt_deg", INI_F64, T(tilt_deg), 0, -90, 90, 0, "0", NULL,
     "the placement's tilt from upright, as the person was asked", "%.3f", NULL},
    {"target", "angle_mdeg", INI_I32, T(angle_mdeg), 0, -3600000, 3600000, 0, "0", NULL,
     "the table's angle", NULL, NULL},
    {"target", "has_angle", INI_U32, T(has_angle), 0, 0, 1, 0, "0", NULL,
     "1: angle_mdeg is the table's (0: taken elsewhere, no turntable)", NULL, NULL},
};
#undef T

int calib_write_target(const struct hal_storage *st, const char *dir, uint32_t view,
                       const struct calib_target_info *t)
{
    static const char header[] =
        "; what this capture shows (scanner calibrate; docs/calibration.md)\n";
    char path[SCAN_DIR_PATH_MAX] = SCAN_FILE_TARGET, buf[512];
    struct target_file f = {.placement = t->placement,
                            .tilt_deg = t->tilt_deg,
                            .angle_mdeg = t->angle_mdeg,
                            .has_angle = 1};
    snprintf(f.target, sizeof(f.target), "%s", t->kind == CALIB_TARGET_SPHERE ? "sphere" : "board");
    int n = ini_schema_write(target_keys, sizeof(target_keys) / sizeof(target_keys[0]), &f, header,
                             NULL, "", buf, sizeof(buf));
    int rc = n < 0 ? n : scan_dir_path(path, sizeof(path), dir, (int)view, SCAN_FILE_TARGET);
    if (rc == 0)
        rc = hal_storage_write_file(st, path, buf, (size_t)n);
    if (rc != 0)
        fprintf(stderr, "scanner: error: cannot write %s: %s\n", path, strerror(-rc));
    return rc;
}

int calib_read_target(const char *dir, uint32_t view, struct calib_target_info *t, char *err,
                      size_t err_len)
{
    char path[SCAN_DIR_PATH_MAX];
    struct target_file f;
    memset(t, 0, sizeof(*t));
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, SCAN_FILE_TARGET);
    if (rc == 0) {
        memset(&f, 0, sizeof(f));
        rc = ini_schema_load(target_keys, sizeof(target_keys) / sizeof(target_keys[0]), &f, path,
                             err, err_len);
    }
    if (rc == -ENOENT) { /* taken elsewhere: a board, its own placement, no angle */
        t->kind = CALIB_TARGET_BOARD;
        t->placement = 1000 + view;
        return 0;
    }
    if (rc != 0)
        return rc;
    t->kind = strcmp(f.target, "sphere") == 0 ? CALIB_TARGET_SPHERE : CALIB_TARGET_BOARD;
    t->placement = f.placement;
    t->tilt_deg = f.tilt_deg;
    t->angle_mdeg = f.angle_mdeg;
    t->has_angle = f.has_angle;
    return 0;
}

int calib_write_file(const struct hal_storage *st, const char *dir, const char *name,
                     const char *from)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), dir, -1, name);
    if (rc == 0)
        rc = scan_dir_copy_file(st, from, path);
    if (rc != 0)
        fprintf(stderr, "scanner: error: cannot copy %s to %s/%s: %s\n", from, dir, name,
                strerror(-rc));
    return rc;
}

int calib_write_guess(const struct hal_storage *st, const char *dir, const struct scan_calib *g)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_CALIBRATION);
    if (rc == 0)
        rc = calib_save(st, path, g,
                        "; the calibration these captures were taken with (only its sizes and\n"
                        "; light count matter to them; scanner calibrate computes the rest)\n");
    if (rc != 0)
        fprintf(stderr, "scanner: error: cannot write %s: %s\n", path, strerror(-rc));
    return rc;
}

int calib_write_svg(const struct hal_storage *st, const char *base, const char *png_path, int width,
                    int height, double px_per_mm)
{
    char path[HAL_MAX_PATH + 8], buf[1024], href[3 * 256 + 1];
    double w = width / px_per_mm, h = height / px_per_mm;
    const char *name = strrchr(png_path, '/');
    name = name != NULL ? name + 1 : png_path;
    /* the picture's name as a URI reference: percent-encoded (RFC 3986) but for the unreserved
     * characters, so that no '"', '<' or '&' of a file name ends up in the XML as markup */
    size_t k = 0;
    for (const unsigned char *c = (const unsigned char *)name; *c != '\0' && k + 4 < sizeof(href);
         c++) {
        if ((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
            strchr("-._~", *c) != NULL)
            href[k++] = (char)*c;
        else
            k += (size_t)snprintf(href + k, sizeof(href) - k, "%%%02X", *c);
    }
    href[k] = '\0';
    int n = snprintf(buf, sizeof(buf),
                     "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                     "<!-- calibration board, true size: print at 100%% -->\n"
                     "<svg xmlns=\"http://www.w3.org/2000/svg\" "
                     "xmlns:xlink=\"http://www.w3.org/1999/xlink\" width=\"%.3fmm\" "
                     "height=\"%.3fmm\" viewBox=\"0 0 %.3f %.3f\">\n"
                     "  <image x=\"0\" y=\"0\" width=\"%.3f\" height=\"%.3f\" "
                     "style=\"image-rendering:pixelated\" xlink:href=\"%s\"/>\n</svg>\n",
                     w, h, w, h, w, h, href);
    snprintf(path, sizeof(path), "%s.svg", base);
    if (n < 0 || (size_t)n >= sizeof(buf))
        return -ENAMETOOLONG;
    return hal_storage_write_file(st, path, buf, (size_t)n);
}
