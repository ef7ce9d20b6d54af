/* The built-in methods' tables, listed once in methods/registry.c. */
#ifndef TCB_METHODS_BUILTIN_H
#define TCB_METHODS_BUILTIN_H

#include "tcb/method.h"

extern const tcb_method_ops tcb_method_oracle;
extern const tcb_method_ops tcb_method_nearest;
extern const tcb_method_ops tcb_method_nricp;
extern const tcb_method_ops tcb_method_atlasnet;
extern const tcb_method_ops tcb_method_dsr;
extern const tcb_method_ops tcb_method_mca;
extern const tcb_method_ops tcb_method_cc;
extern const tcb_method_ops tcb_method_neupig;
extern const tcb_method_ops tcb_method_pdg;
extern const tcb_method_ops tcb_method_dynosurf;
extern const tcb_method_ops tcb_method_external;

#endif
