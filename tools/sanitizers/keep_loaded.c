// LD_PRELOADed into the sanitizer build's tests (scripts/test.sh): dlclose does nothing, so the
// libraries the Vulkan loader and OpenNI2 unload at shutdown (lavapipe, LLVM, the validation
// layer, OpenNI2's drivers) are still mapped when LeakSanitizer walks the heap at exit. Their
// leaks then carry the library's name, which the suppressions of sanitizer_defaults.cpp match; unloaded,
// they show as "<unknown module>" and could not be told apart from mrgi's own.
int dlclose(void* handle) {
  (void)handle;
  return 0;
}
