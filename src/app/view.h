/*
 * app/view.h — rayes view (view.c): a scene rendered progressively in a
 * window (or headless) while a script or the keyboard edits it.
 */
#ifndef RAYES_APP_VIEW_H
#define RAYES_APP_VIEW_H

/* Runs `rayes view ...` (argv[2] on); returns the exit status. */
int cmd_view(int argc, char **argv);

#endif /* RAYES_APP_VIEW_H */
