// A shared library that is not a rig node plugin (in_process_test: the loader
// must refuse it by name, not crash).
extern "C" __attribute__((visibility("default"))) int not_a_rig_plugin() { return 42; }
