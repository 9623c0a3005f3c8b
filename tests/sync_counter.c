/* tests/sync_counter.c - an LD_PRELOAD library that counts the fsync and
 * fdatasync calls on write-ahead logs (files ending in "-wal"), then makes
 * them, and writes the count to the file named by $SYNC_COUNT_FILE at exit:
 * the tests' proof that the commits of a .cmdb in WAL mode reach the disk
 * (with SQLite's synchronous OFF, a WAL is never synced). */
#define _GNU_SOURCE /* RTLD_NEXT */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static unsigned long syncs;

/* Counts a sync of fd if it is a write-ahead log. */
static void count(int fd)
{
    char link[64], name[4096];
    snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
    const ssize_t n = readlink(link, name, sizeof name - 1);
    if (n > 4 && memcmp(name + n - 4, "-wal", 4) == 0)
        __atomic_add_fetch(&syncs, 1, __ATOMIC_RELAXED);
}

/* The next definition of name (libc's): copied, as ISO C has no cast from
 * an object pointer to a function pointer. */
static int (*next_sync(const char *name))(int)
{
    void *p = dlsym(RTLD_NEXT, name);
    int (*f)(int);
    memcpy(&f, &p, sizeof f);
    return f;
}

int fsync(int fd)
{
    int (*real)(int) = next_sync("fsync");
    count(fd);
    return real(fd);
}

int fdatasync(int fd)
{
    int (*real)(int) = next_sync("fdatasync");
    count(fd);
    return real(fd);
}

__attribute__((destructor)) static void report(void)
{
    const char *path = getenv("SYNC_COUNT_FILE");
    FILE *f = path ? fopen(path, "w") : NULL;
    if (f) {
        fprintf(f, "%lu\n", syncs);
        fclose(f);
    }
}
