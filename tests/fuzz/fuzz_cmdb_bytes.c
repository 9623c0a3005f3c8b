/* libFuzzer target: a .cmdb file as arbitrary bytes (seeds: small valid
 * files of every format version), read as every reader reads it. Nothing
 * may crash, leak, or resolve a cell to a group the file lacks. */
#define _DEFAULT_SOURCE /* mkstemp */
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "fuzz_read.h"

static char path[64];

static void remove_side_files(void)
{
    char side[96];
    const char *suffixes[] = {"-wal", "-shm", "-journal"};
    for (int k = 0; k < 3; k++) {
        snprintf(side, sizeof side, "%s%s", path, suffixes[k]);
        unlink(side);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_temp_path(path);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0)
        fuzz_fail("cannot write the temporary file");
    remove_side_files();
    fuzz_read_file(path);
    remove_side_files();
    return 0;
}
