#pragma once
// A room low in the order: includes nothing of the rooms.
inline int low() { return 1; }
