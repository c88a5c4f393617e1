// Loads a shared object that carries the library, as Python loads an extension module, and runs
// its job. The plugin (track_plugin) takes in the static libnrslam.a, or links libnrslam.so in a
// shared build: its link fails when the library is not position-independent, and loading it here
// fails when it leaves one of the library's symbols or dependencies unresolved (RTLD_NOW resolves
// all of them at once).
// Usage: load_plugin PLUGIN WORK_FOLDER.
#include <dlfcn.h>

#include <iostream>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: load_plugin PLUGIN WORK_FOLDER\n";
    return 2;
  }
  void* plugin = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  if (plugin == nullptr) {
    std::cerr << "cannot load " << argv[1] << ": " << dlerror() << "\n";
    return 1;
  }
  using Job = int (*)(const char*);
  const auto job = reinterpret_cast<Job>(dlsym(plugin, "TrackSimulatedSequence"));
  if (job == nullptr) {
    std::cerr << argv[1] << " has no TrackSimulatedSequence: " << dlerror() << "\n";
    return 1;
  }
  return job(argv[2]);
}
