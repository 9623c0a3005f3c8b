/* libFuzzer target: the text files a user gives a command. The first byte
 * chooses the reader, the rest is the file's bytes, written to a file in a
 * private directory and read as the command reads it:
 *   0 a palette (--palette FILE: #rrggbb lines), 1 a labels file
 *   (--labels FILE: "ID TEXT" lines), 2 lyapunov's --curves FILE (the CSV
 *   of `continue --curves`), in the grid (S, Omega), as lib/lyapunov reads it. */
#define _DEFAULT_SOURCE /* mkdtemp */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/palette.h"
#include "src/figure_opts.h"
#include "lib/lyapunov.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    char dir[] = "/tmp/cellmap-fuzz-files-XXXXXX";
    if (!mkdtemp(dir) || chdir(dir) != 0)
        abort();
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 65536)
        return 0;
    FILE *f = fopen("f.txt", "wb");
    if (!f || fwrite(data + 1, 1, size - 1, f) != size - 1 || fclose(f) != 0)
        abort();
    char msg[1024];
    switch (data[0] % 3) {
    case 0: {
        cm_palette p;
        memset(&p, 0, sizeof p);
        cm_palette_read("f.txt", &p, msg, sizeof msg);
        break;
    }
    case 1: {
        png_opts po;
        memset(&po, 0, sizeof po);
        png_opts_labels("f.txt", &po, msg, sizeof msg);
        break;
    }
    default: {
        lyap_args a;
        memset(&a, 0, sizeof a);
        snprintf(a.ax[0].name, sizeof a.ax[0].name, "S");
        snprintf(a.ax[1].name, sizeof a.ax[1].name, "Omega");
        a.ax[0].lo = a.ax[1].lo = 0;
        a.ax[0].hi = a.ax[1].hi = 1;
        a.curves[0] = "f.txt";
        a.n_curves = 1;
        overlay ov;
        memset(&ov, 0, sizeof ov);
        lyapunov_read_curves(&a, &ov, msg, sizeof msg);
        lyapunov_overlay_free(&ov);
    }
    }
    return 0;
}
