/* Station configuration files are outside input: the loader must refuse garbage cleanly. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "cli/config.h"
#include "fuzz_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[64];
    if (fuzz_file_write("config", data, size, path)) return 0;
    csf_config c;
    csf_error err;
    csf_config_defaults(&c);
    csf_config_load(&c, path, &err);
    fuzz_file_remove(path);
    return 0;
}
