/*
 * io/zip.h — one member of a zip file, read whole (RenderMan's archive
 * names "file.zip!member.rib", which RenderMan for Maya writes).
 */
#ifndef RAYES_IO_ZIP_H
#define RAYES_IO_ZIP_H

#include <stddef.h>

/* The member named member of the zip file at path, stored or deflated:
 * a new buffer of *size bytes, or NULL with a one-line reason in err (no
 * such file or member, an unsupported method, a damaged or too large
 * file; at most max_bytes uncompressed). */
unsigned char *io_zip_member(const char *path, const char *member, size_t max_bytes,
                             size_t *size, char *err, size_t err_size);

#endif /* RAYES_IO_ZIP_H */
