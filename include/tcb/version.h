/* tcbench — the version of this source tree. */
#ifndef TCB_VERSION_H
#define TCB_VERSION_H

#define TCB_VERSION "0.1.0"

#endif
