/* libFuzzer target: the explore session language. Each input is a script
 * run in a new session (a new database in a private directory, coarse
 * cells, at most 2^14 new cells a command) line by line, as `cellmap
 * explore` runs it; a failing line reports and the session goes on.
 * Lines with a '/' (paths out of the directory) and render lines (OpenGL,
 * tested elsewhere) are skipped. */
#define _DEFAULT_SOURCE /* mkdtemp */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "src/explore.h"

static void empty_directory(void)
{
    DIR *d = opendir(".");
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            unlink(e->d_name);
    if (d)
        closedir(d);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    char dir[] = "/tmp/cellmap-fuzz-session-XXXXXX";
    if (!mkdtemp(dir) || chdir(dir) != 0)
        abort();
    return 0;
}

static int skipped(const char *line)
{
    while (*line == ' ' || *line == '\t')
        line++;
    return strchr(line, '/') || strncmp(line, "render", 6) == 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096)
        return 0;
    session_options o;
    memset(&o, 0, sizeof o);
    o.path = "session.cmdb";
    o.mo.name = "microchaos-pd";
    o.cell_size[0] = 5;
    o.cell_size[1] = 1;
    o.n_cell_size = 2;
    o.threads = 1;
    o.max_new_cells = UINT64_C(1) << 14;
    explore s;
    empty_directory();
    if (explore_open(&s, &o, NULL) != EXIT_OK)
        abort(); /* the options are fixed and valid */
    char *text = malloc(size + 1), msg[1024];
    memcpy(text, data, size);
    text[size] = '\0';
    int lines = 0;
    for (char *line = text, *next; line && lines < 64 && !s.quit; line = next, lines++) {
        next = strchr(line, '\n');
        if (next)
            *next++ = '\0';
        if (!skipped(line))
            explore_exec(&s, line, msg, sizeof msg);
    }
    explore_close(&s, msg, sizeof msg);
    free(text);
    return 0;
}
