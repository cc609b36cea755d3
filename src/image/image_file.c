/*
 * image/image_file.c — what the image writers (image_exr.c, image_png.c)
 * share: the error messages, and the atomic write through a temporary
 * file. It calls no writer.
 *
 * Atomicity: a writer never opens its target. image_write_via_temp creates
 * "PATH.tmp-<pid>-<n>" beside it (same directory, so the rename cannot
 * cross file systems), lets the format's writer fill it, and renames it
 * over the target only when every byte reached the kernel. On any failure
 * the temporary file is unlinked and the target, old or absent, is left as
 * it was. There is no fsync: a crash of the machine may lose the new file,
 * but never exposes a partial one under the target's name.
 *
 * Thread-safety: reentrant. The only shared state is the atomic counter
 * that makes temporary names unique among threads of this process (the pid
 * makes them unique among processes; O_EXCL catches anything else).
 */
#include "image/image_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static atomic_ulong n_temp_files;

/* Library messages may carry newlines; the contract is one line. */
static void flatten_line(char *s)
{
    size_t n = strlen(s);
    for (size_t i = 0; i < n; i++)
        if (s[i] == '\n' || s[i] == '\r' || s[i] == '\t')
            s[i] = ' ';
    while (n > 0 && s[n - 1] == ' ')
        s[--n] = '\0';
}

/* Fills err (if there is room) with the formatted message, on one line. */
void image_set_error(char *err, size_t err_size, const char *fmt, ...)
{
    if (!err || err_size == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, err_size, fmt, ap);
    va_end(ap);
    flatten_line(err);
}

/* As image_set_error, followed by ": " and the text of errnum. */
void image_set_errno_error(char *err, size_t err_size, int errnum, const char *fmt, ...)
{
    if (!err || err_size == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, err_size, fmt, ap);
    va_end(ap);
    char buf[128];
    /* The GNU strerror_r (we build with _GNU_SOURCE) may return a static
     * string instead of filling buf; either way it is thread-safe. */
    const char *text = strerror_r(errnum, buf, sizeof buf);
    size_t used = strlen(err);
    if (used + 1 < err_size)
        snprintf(err + used, err_size - used, ": %s", text);
    flatten_line(err);
}

/* Explains why the temporary file beside path could not be created,
 * naming the directory, since that is what is usually wrong. */
static RayesError report_create_failure(const char *path, int errnum, char *err, size_t err_size)
{
    const char *slash = strrchr(path, '/');
    char dir_path[4096]; /* PATH_MAX; a longer name is only cut in the message */
    if (!slash)
        snprintf(dir_path, sizeof dir_path, ".");
    else /* "/name" lives in "/" */
        snprintf(dir_path, sizeof dir_path, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    struct stat st;
    /* ENOENT also comes from directories that refuse new files (/proc). */
    if (errnum == ENOENT && stat(dir_path, &st) != 0)
        image_set_error(err, err_size, "%s: directory %s does not exist", path, dir_path);
    else if (errnum == ENOTDIR)
        image_set_error(err, err_size, "%s: %s is not a directory", path, dir_path);
    else
        image_set_errno_error(err, err_size, errnum, "%s: cannot create a file in %s", path, dir_path);
    return errnum == ENOMEM ? RAYES_ERROR_OUT_OF_MEMORY : RAYES_ERROR_IO;
}

/* Flushes and closes file; on the first failure fills err. */
static RayesError close_temp(FILE *file, const char *path, RayesError rv, char *err,
                             size_t err_size)
{
    /* fflush, not only fclose, so that its errno is the one reported. */
    if (rv == RAYES_OK && fflush(file) != 0) {
        image_set_errno_error(err, err_size, errno, "%s: cannot write", path);
        rv = RAYES_ERROR_IO;
    }
    if (fclose(file) != 0 && rv == RAYES_OK) {
        image_set_errno_error(err, err_size, errno, "%s: cannot write", path);
        rv = RAYES_ERROR_IO;
    }
    return rv;
}

/* Creates a temporary file beside path, calls write_body(file, path, data,
 * err, err_size) to fill it, and renames it to path if that and the final
 * flush succeed. Returns RAYES_OK, or the first error (its message in err)
 * after removing the temporary file. The file is open for writing only;
 * write_body may use stdio on it or write to fileno(file) directly, but not
 * both, and must not close it. */
RayesError image_write_via_temp(const char *path, ImageBodyWriter write_body, const void *data, char *err,
                             size_t err_size)
{
    size_t tmp_bytes = strlen(path) + 64;
    char *tmp = malloc(tmp_bytes);
    if (!tmp) {
        image_set_error(err, err_size, "%s: out of memory", path);
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    snprintf(tmp, tmp_bytes, "%s.tmp-%ld-%lu", path, (long)getpid(),
             atomic_fetch_add(&n_temp_files, 1));
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
        RayesError rv = report_create_failure(path, errno, err, err_size);
        free(tmp);
        return rv;
    }
    RayesError rv = RAYES_OK;
    FILE *file = fdopen(fd, "wb");
    if (!file) {
        image_set_errno_error(err, err_size, errno, "%s: cannot write", path);
        close(fd);
        rv = RAYES_ERROR_IO;
    } else {
        rv = write_body(file, path, data, err, err_size);
        rv = close_temp(file, path, rv, err, err_size);
    }
    if (rv == RAYES_OK && rename(tmp, path) != 0) {
        image_set_errno_error(err, err_size, errno, "%s: cannot replace it", path);
        rv = RAYES_ERROR_IO;
    }
    if (rv != RAYES_OK)
        unlink(tmp);
    free(tmp);
    return rv;
}
