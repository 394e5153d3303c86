/* Fuzz target: a scan directory's per-view metadata (view_NNN/view.ini), every key, read by
 * scanner process and resume through scan_dir. */
#define _GNU_SOURCE
#include "fuzz_input.h"

#include "scan_dir.h"

#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct scan_dir_view v;
    char err[512] = "";
    int rc = scan_dir_read_view_file(fuzz_path(data, size), 0, &v, err, sizeof(err));
    FUZZ_EXPECT(rc <= 0);
    FUZZ_EXPECT(rc == 0 || strlen(err) > 0);
    FUZZ_EXPECT(rc != 0 || v.frame_count <= SCAN_DIR_MAX_FRAMES);
    return 0;
}
