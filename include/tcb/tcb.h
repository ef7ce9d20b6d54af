/* tcbench — umbrella header. */
#ifndef TCB_TCB_H
#define TCB_TCB_H

#include "tcb/error.h"
#include "tcb/rng.h"
#include "tcb/progress.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"
#include "tcb/nn.h"
#include "tcb/geometry.h"
#include "tcb/mesh.h"
#include "tcb/sequence.h"
#include "tcb/align.h"
#include "tcb/synth.h"
#include "tcb/split.h"
#include "tcb/metrics.h"
#include "tcb/method.h"
#include "tcb/registry.h"
#include "tcb/results.h"
#include "tcb/config.h"
#include "tcb/runner.h"
#include "tcb/inspect.h"
#include "tcb/frames.h"
#include "tcb/npy.h"
#include "tcb/score.h"
#include "tcb/compare.h"
#include "tcb/report.h"
#include "tcb/binding.h"

#define TCB_VERSION "0.1.0"

#endif
