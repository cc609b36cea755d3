/*
 * io/rib_cond.h — RIB conditional expressions (IfBegin, ElseIf).
 */
#ifndef RAYES_IO_RIB_COND_H
#define RAYES_IO_RIB_COND_H

/* The truth of a conditional block's expression into *value; 0, or -1
 * when the expression is not one this reader understands (*value then
 * 1: the branch is read). */
int rib_condition(const char *expr, int *value);

#endif /* RAYES_IO_RIB_COND_H */
