/* scanner-calibrate: the calibration's own program, run by `scanner calibrate` (so that a scan
 * never loads OpenCV): scanner calibrate [verify | board] --config F [--out P] [--dir D |
 * --from D] (docs/calibration.md). */
#define _POSIX_C_SOURCE 200809L
#include "calibrate.h"
#include "rig.h"
#include "scan.h"
#include "storage_posix.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

/* scanner calibrate [verify | board | import --opencv D] --config F [--out P] [--dir D |
 * --from D [--add D2] [--json]] */
int main(int argc, char **argv)
{
    static struct app_config cfg;
    static struct scan_calib calib;
    const char *config_path = NULL, *out = NULL, *dir = NULL, *from = NULL, *what = "";
    const char *opencv = NULL, *added = NULL;
    int json = 0;
    int first = 2;
    if (argc > 2 && (strcmp(argv[2], "verify") == 0 || strcmp(argv[2], "board") == 0 ||
                     strcmp(argv[2], "import") == 0))
        what = argv[first++];
    for (int i = first; i < argc; i++) {
        if (strcmp(argv[i], "--config") == 0 && i + 1 < argc)
            config_path = argv[++i];
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
            out = argv[++i];
        else if (strcmp(argv[i], "--dir") == 0 && i + 1 < argc)
            dir = argv[++i];
        else if (strcmp(argv[i], "--from") == 0 && i + 1 < argc)
            from = argv[++i];
        else if (strcmp(argv[i], "--add") == 0 && i + 1 < argc && what[0] == '\0')
            added = argv[++i];
        else if (strcmp(argv[i], "--json") == 0 && what[0] != 'b' && what[0] != 'i')
            json = 1;
        else if (strcmp(argv[i], "--opencv") == 0 && i + 1 < argc && what[0] == 'i')
            opencv = argv[++i];
        else {
            fprintf(stderr, "scanner: calibrate: unknown argument '%s'\n", argv[i]);
            return 2;
        }
    }
    char err[512];
    if (config_path == NULL || (what[0] != 'v' && out == NULL)) {
        fprintf(stderr, "scanner: calibrate: --config FILE%s is required\n",
                what[0] == 'v' ? "" : " and --out FILE");
        return 2;
    }
    /* captures on disk: the keys that only drive the rig are not needed */
    int offline = from != NULL || strcmp(what, "import") == 0;
    if ((offline ? config_load_offline : config_load)(&cfg, config_path, err, sizeof(err)) != 0) {
        fprintf(stderr, "scanner: error: %s\n", err);
        return 2;
    }
    struct hal_storage st;
    storage_posix_init(&st);
    if (strcmp(what, "board") == 0)
        return calibrate_print_board(&st, &cfg, out) == 0 ? 0 : 1;
    if (strcmp(what, "import") == 0) {
        if (opencv == NULL) {
            fprintf(stderr, "scanner: calibrate import: --opencv DIR is required (captures made "
                            "with OpenCV's GrayCodePattern, a folder a board pose)\n");
            return 2;
        }
        return calibrate_import_opencv(&st, &cfg, opencv, out) == 0 ? 0 : 1;
    }
    if (added != NULL && from == NULL) {
        fprintf(stderr, "scanner: calibrate: --add DIR2 goes with --from DIR (the captures of "
                        "the first calibration)\n");
        return 2;
    }
    if (from != NULL)
        return calibrate_solve(&st, &cfg, from, added, out, json) == 0 ? 0 : 1;
    int rc = calib_load(&calib, cfg.calibration_file, cfg.light_count, err, sizeof(err));
    if (rc == -ENOENT && what[0] != 'v') {
        calibrate_guess(&cfg, &calib); /* a new rig: nothing calibrated yet */
        rc = 0;
    }
    if (rc == 0)
        rc = scan_check(&cfg.scan, &calib, err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "scanner: error: %s\n", err);
        return 2;
    }
    if (what[0] != 'v') /* the projector's sequence is the calibration's: rows too */
        calib_capture_params(&cfg, &cfg.scan);
    char dir_buf[HAL_MAX_PATH];
    if (dir == NULL && out != NULL) {
        calib_path_beside(out, "-captures", dir_buf, sizeof(dir_buf));
        dir = dir_buf;
    }
    rc = rig_up(&cfg, &calib);
    if (rc == 0)
        rc = what[0] == 'v' ? calibrate_verify(rig_hal(), &cfg, &calib, json)
                            : calibrate_capture(rig_hal(), &cfg, &calib, dir, json);
    rig_down();
    if (rc == 0 && what[0] != 'v')
        rc = calibrate_solve(&st, &cfg, dir, NULL, out, json);
    return rc == 0 ? 0 : 1;
}
