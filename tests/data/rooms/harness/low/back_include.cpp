// Includes a header of a room above its own: the build must refuse it.
#include "harness/high/high.h"
int back() { return high(); }
