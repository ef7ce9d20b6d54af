/* The work below which an OpenMP loop of the layers runs on one thread: a
 * thread team's start and barrier (a few microseconds) cost more than
 * splitting 32 768 multiply-adds or element operations saves. One value
 * for neural/ and the layers built on it (the atlas decoder), so that a
 * change of it reaches every loop. */
#ifndef TCB_NEURAL_PARALLEL_H
#define TCB_NEURAL_PARALLEL_H

#define TCB_PAR_MIN 32768.0

#endif
