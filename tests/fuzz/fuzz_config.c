/* Fuzz target: the scanner's INI config parser (app/config.c on inih). */
#define _GNU_SOURCE
#include "fuzz_input.h"

#include "config.h"

#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct app_config cfg;
    char err[512] = "";
    const char *path = fuzz_path(data, size);
    int rc = config_load(&cfg, path, err, sizeof(err));
    FUZZ_EXPECT(rc == 0 || (rc < 0 && strstr(err, path) != NULL));
    return 0;
}
