/* libFuzzer target: whole commands as a user runs them. The first byte
 * chooses the command (export, info, solve, sweep, the analysis commands,
 * ...), the rest is its arguments, one per line, run in a private
 * directory holding a.cmdb (the seed cluster) and t.txt (a text file, as a
 * palette, labels, curves or script file is). What the run must hold, else
 * the target aborts: a.cmdb byte-identical afterwards (no command may
 * change a file it only reads), an exit status of 0, 1, 2 or 130, and no
 * OUT.tmp-* left behind. Each command is interrupted (Ctrl-C, as SIGINT)
 * after 200 ms, so that arguments asking for long work end quickly; a
 * command that cannot be interrupted shows up as a time-out. Arguments
 * with a '/' (paths out of the directory) and figures (--png, --svg:
 * OpenGL, tested elsewhere) are skipped, and so are solve and explore
 * lines that name a.cmdb (which they may write). Standard input is
 * /dev/null. */
#define _DEFAULT_SOURCE /* mkdtemp */
#include <dirent.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "src/commands.h"
#include "src/interrupt.h"

typedef int (*command_fn)(int, char **);
static const struct {
    const char *name;
    command_fn run;
} commands[] = {
    {"export", cmd_export},       {"info", cmd_info},         {"solve", cmd_solve},
    {"sweep", cmd_sweep},         {"models", cmd_models},     {"orbit", cmd_orbit},
    {"fixed-points", cmd_fixed_points}, {"lyapunov", cmd_lyapunov}, {"simulate", cmd_simulate},
    {"continue", cmd_continue},   {"amplitude", cmd_amplitude}, {"escape", cmd_escape},
    {"stability", cmd_stability}, {"horseshoe", cmd_horseshoe}, {"partition", cmd_partition},
    {"bifurcation", cmd_bifurcation}, {"explore", cmd_explore},
};
#define N_COMMANDS (sizeof commands / sizeof commands[0])

static unsigned char *seed;
static size_t seed_size;
static timer_t timer;

static unsigned char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *buf = malloc(1 << 20);
    *size = buf ? fread(buf, 1, 1 << 20, f) : 0;
    fclose(f);
    return buf;
}

static void write_all(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0)
        abort();
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    seed = read_all(FUZZ_SEED_CMDB, &seed_size);
    char dir[] = "/tmp/cellmap-fuzz-commands-XXXXXX";
    struct sigevent ev;
    memset(&ev, 0, sizeof ev);
    ev.sigev_notify = SIGEV_SIGNAL;
    ev.sigev_signo = SIGINT;
    if (!seed || !seed_size || !mkdtemp(dir) || chdir(dir) != 0 ||
        !freopen("/dev/null", "r", stdin) ||
        timer_create(CLOCK_MONOTONIC, &ev, &timer) != 0)
        abort();
    write_all("a.cmdb", seed, seed_size);
    write_all("t.txt", "#112233\n#445566\n1 first\n", 25);
    return 0;
}

/* Removes what the command wrote; aborts on a temporary file left behind. */
static void clean_directory(void)
{
    DIR *d = opendir(".");
    struct dirent *e;
    bool left = false;
    while (d && (e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0 ||
            strcmp(e->d_name, "a.cmdb") == 0 || strcmp(e->d_name, "t.txt") == 0)
            continue;
        left = left || strstr(e->d_name, ".tmp-") != NULL;
        unlink(e->d_name);
        rmdir(e->d_name);
    }
    if (d)
        closedir(d);
    if (left)
        abort();
}

static void arm(long ms)
{
    struct itimerspec t;
    memset(&t, 0, sizeof t);
    t.it_value.tv_sec = ms / 1000;
    t.it_value.tv_nsec = (ms % 1000) * 1000000L;
    timer_settime(timer, 0, &t, NULL);
}

static bool skipped(const char *cmd, const char *arg)
{
    const bool writes = strcmp(cmd, "solve") == 0 || strcmp(cmd, "explore") == 0;
    return (writes && strstr(arg, "a.cmdb")) || strchr(arg, '/') || strcmp(arg, "--png") == 0 || strcmp(arg, "--svg") == 0 ||
           strncmp(arg, "--png=", 6) == 0 || strncmp(arg, "--svg=", 6) == 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 1024)
        return 0;
    char *text = malloc(size), *argv[26];
    memcpy(text, data + 1, size - 1);
    text[size - 1] = '\0';
    const unsigned which = data[0] % N_COMMANDS;
    int argc = 0;
    argv[argc++] = (char *)commands[which].name;
    for (char *p = text; p && argc < 25; argc++) {
        argv[argc] = p;
        p = strchr(p, '\n');
        if (p)
            *p++ = '\0';
        if (skipped(argv[0], argv[argc])) {
            free(text);
            return 0;
        }
    }
    argv[argc] = NULL;
    interrupt_clear();
    interrupt_catch(); /* a SIGINT before the command catches it is its request too */
    arm(200);
    const int rc = commands[which].run(argc - 1, argv + 1);
    arm(0);
    interrupt_clear();
    free(text);
    size_t now_size = 0;
    unsigned char *now = read_all("a.cmdb", &now_size);
    const bool unchanged = now && now_size == seed_size && memcmp(now, seed, seed_size) == 0;
    free(now);
    if (!unchanged) /* a command changed the file it reads */
        abort();
    clean_directory();
    if (rc != 0 && rc != 1 && rc != 2 && rc != 130)
        abort();
    return 0;
}
