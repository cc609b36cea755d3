/*
 * app/assemble.h — `rayes assemble OUT.exr PART.exr...`: the crops of one
 * frame (renders with --crop, each an EXR whose data window is its crop of
 * the display window) put together into one EXR. Parts that tile the frame
 * give the bytes of the whole render (every pixel is the same in a crop
 * and in the whole frame, and half values survive the round trip).
 */
#ifndef RAYES_APP_ASSEMBLE_H
#define RAYES_APP_ASSEMBLE_H

/* The assemble command; returns the exit status (0, 1 bad input or a
 * failed write, 2 usage). */
int cmd_assemble(int argc, char **argv);

#endif
