/*
 * io/zip.c — one member of a zip file (zip.h): the end of central
 * directory record, the central directory's entry of that name, its local
 * header, then the data stored or deflated (zlib's raw inflate). Zip64,
 * encryption and other methods are refused with a line saying so. Every
 * offset and size is checked against the file: a damaged file is an
 * error, never a read out of bounds.
 */
#include "io/zip.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

static unsigned u16(const unsigned char *p)
{
    return (unsigned)p[0] | (unsigned)p[1] << 8;
}

static uint32_t u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The whole file, at most limit bytes; NULL on error. */
static unsigned char *slurp(const char *path, size_t limit, size_t *size, char *err, size_t n)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, n, "%s: cannot open the file", path);
        return NULL;
    }
    long len = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    unsigned char *buf = NULL;
    if (len < 0 || (unsigned long)len > limit)
        snprintf(err, n, "%s: %s", path, len < 0 ? "cannot read the file" : "too large");
    else if (!(buf = malloc(len ? (size_t)len : 1)))
        snprintf(err, n, "%s: out of memory", path);
    else if (fseek(f, 0, SEEK_SET) != 0 || fread(buf, 1, (size_t)len, f) != (size_t)len) {
        snprintf(err, n, "%s: cannot read the file", path);
        free(buf);
        buf = NULL;
    }
    fclose(f);
    *size = len > 0 ? (size_t)len : 0;
    return buf;
}

/* Inflates raw deflate data into out (exactly want bytes); 0 or -1. */
static int inflate_raw(const unsigned char *in, size_t in_size, unsigned char *out, size_t want)
{
    z_stream z;
    memset(&z, 0, sizeof z);
    if (inflateInit2(&z, -15) != Z_OK)
        return -1;
    z.next_in = (unsigned char *)in;
    z.avail_in = (uInt)in_size;
    z.next_out = out;
    z.avail_out = (uInt)want;
    int ret = inflate(&z, Z_FINISH);
    size_t got = want - z.avail_out;
    inflateEnd(&z);
    return ret == Z_STREAM_END && got == want ? 0 : -1;
}

unsigned char *io_zip_member(const char *path, const char *member, size_t max_bytes,
                             size_t *size, char *err, size_t err_size)
{
    size_t len;
    unsigned char *zip = slurp(path, max_bytes, &len, err, err_size);
    if (!zip)
        return NULL;
    unsigned char *out = NULL;
    const char *why = NULL;
    /* the end of central directory record: 22 bytes and a comment */
    size_t eocd = len >= 22 ? len - 22 : 0;
    while (len >= 22 && u32(zip + eocd) != 0x06054b50 && eocd > 0 && len - eocd < 22 + 65535)
        eocd--;
    if (len < 22 || u32(zip + eocd) != 0x06054b50) {
        why = "not a zip file (no end of central directory)";
        goto done;
    }
    size_t entries = u16(zip + eocd + 10), dir = u32(zip + eocd + 16), mlen = strlen(member);
    size_t at = dir;
    for (size_t k = 0; k < entries; k++) {
        if (at + 46 > len || u32(zip + at) != 0x02014b50) {
            why = "a damaged central directory";
            goto done;
        }
        size_t nlen = u16(zip + at + 28), extra = u16(zip + at + 30), comment = u16(zip + at + 32);
        if (at + 46 + nlen > len) {
            why = "a damaged central directory";
            goto done;
        }
        if (nlen == mlen && memcmp(zip + at + 46, member, mlen) == 0) {
            unsigned flags = u16(zip + at + 8), method = u16(zip + at + 10);
            size_t csize = u32(zip + at + 20), usize = u32(zip + at + 24);
            size_t local = u32(zip + at + 42);
            if (flags & 1) {
                why = "the member is encrypted";
            } else if (method != 0 && method != 8) {
                why = "the member's compression method is not stored or deflate";
            } else if (csize == 0xffffffffu || usize == 0xffffffffu || local == 0xffffffffu) {
                why = "zip64 members are not read";
            } else if (usize > max_bytes) {
                why = "the member is too large";
            } else if (local + 30 > len || u32(zip + local) != 0x04034b50) {
                why = "a damaged local header";
            } else {
                size_t data = local + 30 + u16(zip + local + 26) + u16(zip + local + 28);
                if (data > len || csize > len - data || (method == 0 && csize != usize))
                    why = "a damaged member";
                else if (!(out = malloc(usize ? usize : 1)))
                    why = "out of memory";
                else if (method == 0)
                    memcpy(out, zip + data, usize);
                else if (inflate_raw(zip + data, csize, out, usize) != 0)
                    why = "the member does not inflate";
                if (why) {
                    free(out);
                    out = NULL;
                }
            }
            *size = usize;
            goto done;
        }
        at += 46 + nlen + extra + comment;
    }
    why = "no such member";
done:
    if (why)
        snprintf(err, err_size, "%s: %s%s%s", path, why,
                 strcmp(why, "no such member") == 0 ? " " : "",
                 strcmp(why, "no such member") == 0 ? member : "");
    free(zip);
    return out;
}
