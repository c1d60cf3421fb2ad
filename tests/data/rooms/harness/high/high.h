#pragma once
// A room above low: it may include low's headers.
#include "harness/low/low.h"
inline int high() { return low() + 1; }
