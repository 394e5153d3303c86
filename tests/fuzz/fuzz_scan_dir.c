/* Fuzz target: the scan directory reader on a directory built from the input, frames included.
 * The input is a view.ini, a NUL byte, then the bytes of a frame, kept as frame_00.png,
 * frame_01.pgm.zst and frame_02.ppm (32 x 24 frames expected), as `scanner process` meets them
 * on disk. */
#define _GNU_SOURCE
#include "fuzz_input.h"

#include "scan_dir.h"

#include <string.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#define W 32u
#define H 24u

static void put(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (f == NULL || fwrite(data, 1, size, f) != size)
        abort();
    fclose(f);
}

static char dir[64];

/* The directory goes when the run ends: a replay of the corpus must not leave it in /tmp. */
static void remove_dir(void)
{
    char path[SCAN_DIR_PATH_MAX];
    scan_dir_path(path, sizeof(path), dir, 0, "view.ini");
    unlink(path);
    for (uint32_t f = 0; f < 3; f++) {
        scan_dir_find_frame(path, sizeof(path), dir, 0, f);
        unlink(path);
    }
    snprintf(path, sizeof(path), "%s/view_000", dir);
    rmdir(path);
    rmdir(dir);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct scan_dir_view v;
    static uint8_t pixels[W * H * 3];
    char path[SCAN_DIR_PATH_MAX], err[SCAN_DIR_PATH_MAX + 256] = "";
    if (dir[0] == '\0') {
        snprintf(dir, sizeof(dir), "/tmp/fuzz-scan-dir-%d", (int)getpid());
        snprintf(path, sizeof(path), "%s/view_000", dir);
        mkdir(dir, 0700);
        mkdir(path, 0700);
        atexit(remove_dir);
    }
    const uint8_t *nul = memchr(data, 0, size);
    size_t ini_len = nul != NULL ? (size_t)(nul - data) : size;
    scan_dir_path(path, sizeof(path), dir, 0, "view.ini");
    put(path, data, ini_len);
    /* the same bytes as a PNG, a zstd PGM and a raw PPM frame: every reader sees them */
    static const enum scan_frame_format formats[3] = {SCAN_FRAMES_PNG, SCAN_FRAMES_ZSTD,
                                                      SCAN_FRAMES_PNM};
    static const char *const names[3] = {"frame_00.png: ", "frame_01.pgm.zst: ", "frame_02.ppm: "};
    for (uint32_t f = 0; f < 3; f++) {
        scan_dir_frame_path(path, sizeof(path), dir, 0, f, formats[f], f == 2 ? 3 : 1);
        put(path, nul != NULL ? nul + 1 : data, nul != NULL ? size - ini_len - 1 : 0);
    }

    int rc = scan_dir_read_view(dir, 0, &v, err, sizeof(err));
    FUZZ_EXPECT(rc <= 0 && (rc == 0 || strlen(err) > 0));
    FUZZ_EXPECT(rc != 0 || (v.index == 0 && v.frame_count <= SCAN_DIR_MAX_FRAMES));
    for (uint32_t f = 0; f < 3; f++)
        for (uint32_t channels = 1; channels <= 3; channels += 2) {
            err[0] = '\0';
            rc = scan_dir_read_frame(dir, 0, f, pixels, sizeof(pixels), W, H, channels, err,
                                     sizeof(err));
            FUZZ_EXPECT(rc <= 0 && (rc == 0 || strstr(err, names[f]) != NULL));
        }
    return 0;
}
