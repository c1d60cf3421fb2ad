// Includes the reference controller: the harness may not, at all.
#include "controller/spray_controller.h"
