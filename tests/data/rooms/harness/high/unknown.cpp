// Includes a header that belongs to no room.
#include "harness/nowhere/lost.h"
