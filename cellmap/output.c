#define _DEFAULT_SOURCE /* readlink, mkstemp, flock */
#include "cellmap/output.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

bool cm_output_names_stdout(const char *path)
{
    return path && (strcmp(path, "-") == 0 || strcmp(path, "/dev/stdout") == 0 ||
           strcmp(path, "/dev/fd/1") == 0 || strcmp(path, "/proc/self/fd/1") == 0);
}

/* Follows the symlinks at path into out (at most 40, as the kernel does).
 * Paths under /proc are kept as they are: their links name open files
 * ("pipe:[..]"), not paths. */
static cm_status follow_links(const char *path, char *out, char *msg, size_t msg_size)
{
    snprintf(out, CM_OUTPUT_PATH_MAX, "%s", path);
    for (int hops = 0; hops < 40; hops++) {
        struct stat sb;
        if (strncmp(out, "/proc/", 6) == 0 || lstat(out, &sb) != 0 || !S_ISLNK(sb.st_mode))
            return CM_OK;
        char target[CM_OUTPUT_PATH_MAX];
        const ssize_t n = readlink(out, target, sizeof target - 1);
        if (n < 0)
            return cm_fail(CM_EIO, msg, msg_size, "cannot read the symlink %s: %s", out,
                           strerror(errno));
        target[n] = '\0';
        if (target[0] == '/') {
            snprintf(out, CM_OUTPUT_PATH_MAX, "%s", target);
            continue;
        }
        char *slash = strrchr(out, '/'); /* relative to the link's directory */
        char joined[2 * CM_OUTPUT_PATH_MAX];
        snprintf(joined, sizeof joined, "%.*s%s", slash ? (int)(slash - out + 1) : 0, out, target);
        if (strlen(joined) >= CM_OUTPUT_PATH_MAX)
            return cm_fail(CM_EINVAL, msg, msg_size, "the symlink %s leads to too long a path",
                           path);
        memcpy(out, joined, strlen(joined) + 1);
    }
    return cm_fail(CM_EINVAL, msg, msg_size, "%s: too many levels of symlinks", path);
}

cm_status cm_output_fail(const char *path, int err, char *msg, size_t msg_size)
{
    const char *slash = strrchr(path, '/');
    char dir[CM_OUTPUT_PATH_MAX];
    if (!slash)
        snprintf(dir, sizeof dir, "the current directory");
    else
        snprintf(dir, sizeof dir, "the directory %.*s", slash == path ? 1 : (int)(slash - path),
                 path);
    switch (err) {
    case ENOENT:
    case ENOTDIR:
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "cannot write %s: %s does not exist (%s); create it or give a path in an "
                       "existing directory",
                       path, dir, strerror(err));
    case EACCES:
    case EPERM:
    case EROFS:
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "cannot write %s: %s is not writable (%s); give a path in a writable "
                       "directory",
                       path, dir, strerror(err));
    case ENOSPC:
    case EDQUOT:
    case EFBIG:
        return cm_fail(CM_EIO, msg, msg_size,
                       "cannot write %s: %s; free space on its disk (or raise the quota) or give "
                       "a path on another disk",
                       path, strerror(err));
    default:
        return cm_fail(CM_EIO, msg, msg_size, "cannot write %s: %s", path,
                       strerror(err ? err : EIO));
    }
}

/* Whether process pid may still be running on this machine. */
static bool process_runs(long pid)
{
    return pid > 0 && pid <= INT_MAX && (kill((pid_t)pid, 0) == 0 || errno == EPERM);
}

/* Whether the file name in dir may be removed as a killed run's: it does
 * not exist, or it is a regular file of ours that no process holds locked. */
static bool stale_file(int dir, const char *name)
{
    struct stat sb;
    if (fstatat(dir, name, &sb, AT_SYMLINK_NOFOLLOW) != 0)
        return errno == ENOENT; /* nothing to keep */
    if (!S_ISREG(sb.st_mode) || sb.st_uid != geteuid())
        return false;
    const int fd = openat(dir, name, O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0)
        return false;
    const bool unlocked = flock(fd, LOCK_EX | LOCK_NB) == 0;
    close(fd);
    return unlocked;
}

/* Removes the temporary files base.tmp-N[-wal|-shm|-journal] in dir of
 * killed runs: N no longer runs here and nobody holds base.tmp-N's lock. */
static void remove_stale_temps(const char *dest)
{
    const char *slash = strrchr(dest, '/');
    char dirname[CM_OUTPUT_PATH_MAX], prefix[CM_OUTPUT_PATH_MAX];
    snprintf(dirname, sizeof dirname, "%.*s", slash ? (int)(slash - dest) + (slash == dest) : 1,
             slash ? dest : ".");
    snprintf(prefix, sizeof prefix, "%s.tmp-", slash ? slash + 1 : dest);
    const size_t np = strlen(prefix);
    DIR *d = opendir(dirname);
    if (!d)
        return;
    const struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (strncmp(e->d_name, prefix, np) != 0)
            continue;
        char *end;
        errno = 0;
        const long pid = strtol(e->d_name + np, &end, 10);
        if (end == e->d_name + np || errno || pid == (long)getpid() || process_runs(pid))
            continue;
        if (*end && strcmp(end, "-wal") != 0 && strcmp(end, "-shm") != 0 &&
            strcmp(end, "-journal") != 0)
            continue;
        char main_file[CM_OUTPUT_PATH_MAX];
        snprintf(main_file, sizeof main_file, "%.*s", (int)(end - e->d_name), e->d_name);
        if (stale_file(dirfd(d), main_file) && stale_file(dirfd(d), e->d_name))
            unlinkat(dirfd(d), e->d_name, 0);
    }
    closedir(d);
}

/* Creates o->tmp beside the destination, empty and locked. */
static cm_status create_locked_temp(cm_output *o, char *msg, size_t msg_size)
{
    remove_stale_temps(o->dest);
    unlink(o->tmp); /* left by a killed run of a process with our id */
    const int fd = open(o->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
        const int e = errno;
        o->tmp[0] = '\0';
        return cm_output_fail(o->path, e, msg, msg_size);
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) { /* a new file: only a file system without locks */
        close(fd);
        o->lock_fd = -1;
        return CM_OK;
    }
    o->lock_fd = fd;
    o->locked = true;
    return CM_OK;
}

/* A temporary file in $TMPDIR (or /tmp) for an output copied in place. */
static cm_status make_temp(cm_output *o, char *msg, size_t msg_size)
{
    const char *dir = getenv("TMPDIR");
    snprintf(o->tmp, sizeof o->tmp, "%s/cellmap-XXXXXX", dir && *dir ? dir : "/tmp");
    const int fd = mkstemp(o->tmp);
    if (fd < 0) {
        const int e = errno;
        o->tmp[0] = '\0';
        return cm_fail(CM_EIO, msg, msg_size,
                       "cannot create a temporary file for %s in %s: %s (set TMPDIR to a "
                       "writable directory)",
                       o->path, dir && *dir ? dir : "/tmp", strerror(e));
    }
    close(fd);
    return CM_OK;
}

cm_status cm_output_begin(cm_output *o, const char *path, bool needs_regular, char *msg,
                          size_t msg_size)
{
    memset(o, 0, sizeof *o);
    o->path = path;
    o->lock_fd = -1;
    if (!path || !*path)
        return cm_fail(CM_EINVAL, msg, msg_size, "an output file name is empty");
    if (strlen(path) + 32 >= CM_OUTPUT_PATH_MAX)
        return cm_fail(CM_EINVAL, msg, msg_size, "the output file name %.64s... is too long",
                       path);
    if (cm_output_names_stdout(path)) {
        if (needs_regular)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "%s cannot be standard output: this output is a database file; give "
                           "a file name",
                           path);
        o->to_stdout = o->in_place = true;
        snprintf(o->dest, sizeof o->dest, "standard output");
        return make_temp(o, msg, msg_size);
    }
    cm_status st = follow_links(path, o->dest, msg, msg_size);
    if (st != CM_OK)
        return st;
    struct stat sb;
    const bool exists = stat(o->dest, &sb) == 0;
    if (exists && S_ISDIR(sb.st_mode))
        return cm_fail(CM_EINVAL, msg, msg_size, "%s is a directory; give a file name in it",
                       path);
    if ((exists && !S_ISREG(sb.st_mode)) || strncmp(o->dest, "/proc/", 6) == 0) {
        if (needs_regular)
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "%s is not a regular file (a device, FIFO or socket); this output is "
                           "a database file: give a file name",
                           path);
        o->in_place = true; /* never replaced: the bytes are copied in */
        return make_temp(o, msg, msg_size);
    }
    if (strlen(o->dest) + 32 >= sizeof o->tmp)
        return cm_fail(CM_EINVAL, msg, msg_size, "the output path of %.64s... is too long", path);
    snprintf(o->tmp, sizeof o->tmp, "%.4150s.tmp-%ld", o->dest, (long)getpid());
    return create_locked_temp(o, msg, msg_size);
}

/* Copies the temporary file into the open destination f. */
static cm_status copy_into(const cm_output *o, FILE *f, char *msg, size_t msg_size)
{
    FILE *in = fopen(o->tmp, "rb");
    if (!in)
        return cm_fail(CM_EIO, msg, msg_size, "cannot read back %s: %s", o->tmp, strerror(errno));
    char buf[1 << 16];
    size_t n;
    int error = 0;
    while (!error && (n = fread(buf, 1, sizeof buf, in)) > 0)
        if (fwrite(buf, 1, n, f) != n)
            error = errno ? errno : EIO;
    if (!error && ferror(in))
        error = EIO;
    fclose(in);
    if (!error && fflush(f) != 0)
        error = errno ? errno : EIO;
    if (error)
        return cm_output_fail(o->to_stdout ? "standard output" : o->path, error, msg, msg_size);
    return CM_OK;
}

cm_status cm_output_close_stream(const cm_output *o, FILE *f, char *msg, size_t msg_size)
{
    errno = 0;
    int error = fflush(f) != 0 || ferror(f) ? (errno ? errno : EIO) : 0;
    if (fclose(f) != 0 && !error)
        error = errno ? errno : EIO;
    return error ? cm_output_fail(o->path, error, msg, msg_size) : CM_OK;
}

cm_status cm_output_commit(cm_output *o, char *msg, size_t msg_size)
{
    cm_status st = CM_OK;
    if (!o->in_place) {
        if (rename(o->tmp, o->dest) != 0)
            st = cm_output_fail(o->path, errno, msg, msg_size);
    } else if (o->to_stdout) {
        errno = 0;
        st = copy_into(o, stdout, msg, msg_size);
    } else {
        /* O_WRONLY without O_CREAT: a device or FIFO, never a new file */
        const int fd = open(o->dest, O_WRONLY | O_TRUNC);
        FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
        if (!f) {
            st = cm_output_fail(o->path, errno, msg, msg_size);
            if (fd >= 0)
                close(fd);
        } else {
            errno = 0;
            st = copy_into(o, f, msg, msg_size);
            if (fclose(f) != 0 && st == CM_OK)
                st = cm_output_fail(o->path, errno, msg, msg_size);
        }
    }
    cm_output_abandon(o);
    return st;
}

void cm_output_abandon(cm_output *o)
{
    if (o && o->tmp[0]) {
        unlink(o->tmp);
        o->tmp[0] = '\0';
    }
    const int fd = o ? cm_output_release(o) : -1;
    if (fd >= 0)
        close(fd);
}

int cm_output_release(cm_output *o)
{
    const int fd = o->locked ? o->lock_fd : -1;
    o->locked = false;
    o->lock_fd = -1;
    o->tmp[0] = '\0';
    return fd;
}

/* Where a file of a command lives: its device and inode when it exists,
 * else its canonical path (the directory resolved, the name kept). */
typedef struct file_key {
    bool compared; /* false: stdout, a device, a FIFO or a socket */
    bool exists;
    dev_t dev;
    ino_t ino;
    char name[CM_OUTPUT_PATH_MAX];
} file_key;

static void file_key_of(const char *path, file_key *k)
{
    memset(k, 0, sizeof *k);
    if (cm_output_names_stdout(path))
        return;
    char dest[CM_OUTPUT_PATH_MAX], ignored[8];
    if (follow_links(path, dest, ignored, sizeof ignored) != CM_OK)
        snprintf(dest, sizeof dest, "%s", path);
    struct stat sb;
    if (stat(dest, &sb) == 0) {
        if (!S_ISREG(sb.st_mode))
            return;
        k->exists = true;
        k->dev = sb.st_dev;
        k->ino = sb.st_ino;
    }
    k->compared = true;
    char resolved[PATH_MAX];
    if (realpath(dest, resolved)) {
        snprintf(k->name, sizeof k->name, "%s", resolved);
        return;
    }
    const char *slash = strrchr(dest, '/');
    char dir[CM_OUTPUT_PATH_MAX];
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - dest) : 1, slash ? dest : ".");
    if (slash == dest)
        snprintf(dir, sizeof dir, "/");
    if (realpath(dir, resolved))
        snprintf(k->name, sizeof k->name, "%.4096s/%.100s", resolved, slash ? slash + 1 : dest);
    else
        snprintf(k->name, sizeof k->name, "%s", dest);
}

static bool same_file(const file_key *a, const file_key *b)
{
    if (!a->compared || !b->compared)
        return false;
    if (a->exists && b->exists)
        return a->dev == b->dev && a->ino == b->ino;
    return strcmp(a->name, b->name) == 0;
}

/* Which part of entry `in` the output key out is: 0 none, 1 the file
 * itself, 2.. its SQLite companion suffixes[part - 2]. */
static const char *const companions[] = {"-wal", "-shm", "-journal"};

static int part_of(const file_key *out, const cm_file_use *in)
{
    file_key k;
    file_key_of(in->path, &k);
    if (same_file(out, &k))
        return 1;
    for (int c = 0; in->database && c < 3; c++) {
        char name[CM_OUTPUT_PATH_MAX];
        snprintf(name, sizeof name, "%.4150s%s", in->path, companions[c]);
        file_key_of(name, &k);
        if (same_file(out, &k))
            return 2 + c;
    }
    return 0;
}

cm_status cm_files_apart(const cm_file_use *files, size_t n, char *msg, size_t msg_size)
{
    for (size_t i = 0; i < n; i++) {
        const cm_file_use *o = &files[i];
        if (!o->path || !o->written)
            continue;
        file_key out;
        file_key_of(o->path, &out);
        for (size_t j = 0; j < n; j++) {
            const cm_file_use *e = &files[j];
            if (j == i || !e->path || (e->written && !e->database && j < i))
                continue; /* a pair of plain outputs is reported once */
            const int part = part_of(&out, e);
            if (part == 0)
                continue;
            if (e->written && !e->database)
                return cm_fail(CM_EINVAL, msg, msg_size,
                               "%s %s and %s %s are the same file: give each output its own "
                               "name",
                               e->what, e->path, o->what, o->path);
            char part_name[64] = "";
            if (part > 1)
                snprintf(part_name, sizeof part_name, "the %s file of ", companions[part - 2]);
            return cm_fail(CM_EINVAL, msg, msg_size,
                           "%s %s is %s%s %s: writing it would destroy what the command %s; "
                           "give %s another file name",
                           o->what, o->path, part_name, e->what, e->path,
                           e->written ? "writes" : "reads", o->what);
        }
    }
    return CM_OK;
}

cm_status cm_stdout_check(char *msg, size_t msg_size)
{
    errno = 0;
    if (fflush(stdout) != 0 || ferror(stdout))
        return cm_fail(CM_EIO, msg, msg_size, "cannot write standard output: %s",
                       strerror(errno ? errno : EIO));
    return CM_OK;
}

cm_status cm_input_open(const char *path, const char *what, uint64_t max_bytes, FILE **f,
                        char *msg, size_t msg_size)
{
    *f = NULL;
    /* opened first, then checked: what is read is what was checked, and
     * O_NONBLOCK keeps a FIFO without a writer from blocking the open */
    const int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return cm_fail(CM_EIO, msg, msg_size, "cannot read %s %s: %s", what, path,
                       strerror(errno));
    struct stat st;
    const char *problem = fstat(fd, &st) != 0     ? strerror(errno)
                          : S_ISDIR(st.st_mode)   ? "it is a directory"
                          : !S_ISREG(st.st_mode)  ? "it is not a regular file (a device or a FIFO)"
                          : (uint64_t)st.st_size > max_bytes ? "it is too large"
                                                             : NULL;
    if (problem) {
        close(fd);
        return cm_fail(CM_EINVAL, msg, msg_size,
                       "%s %s cannot be read: %s; give a text file of at most %llu bytes", what,
                       path, problem, (unsigned long long)max_bytes);
    }
    const int flags = fcntl(fd, F_GETFL);
    if (flags >= 0)
        fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
    *f = fdopen(fd, "r");
    if (!*f) {
        close(fd);
        return cm_fail(CM_EIO, msg, msg_size, "cannot read %s %s: %s", what, path,
                       strerror(errno));
    }
    return CM_OK;
}
