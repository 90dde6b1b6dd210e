// Compiled into every executable of the sanitizer build (MRGI_SANITIZE: the tests, the mrgi tool
// the tests run, the fuzz targets), so the options hold however a program is started (CTest, a
// test's child process, a user's shell) without environment variables.
//   ASan: leaks checked at exit, string functions checked whole.
//   UBSan: a stack trace with every report; the build also has -fno-sanitize-recover, so the first
//   report aborts the program.
//   LeakSanitizer suppressions: third-party libraries only, never a frame of mrgi's: the Vulkan
//   loader, Mesa's lavapipe and its LLVM, the validation layer, OpenNI2 and its drivers, and the
//   display libraries the loader may open. keep_loaded.c keeps them mapped at exit so their leaks
//   carry these names.
extern "C" const char* __asan_default_options() { return "detect_leaks=1:strict_string_checks=1"; }

extern "C" const char* __ubsan_default_options() { return "print_stacktrace=1:halt_on_error=1"; }

extern "C" const char* __lsan_default_suppressions() {
  return "leak:libvulkan.so\n"
         "leak:libvulkan_lvp.so\n"
         "leak:libLLVM\n"
         "leak:libVkLayer_khronos_validation.so\n"
         "leak:libOpenNI2.so\n"
         "leak:*/OpenNI2/Drivers/*\n"
         "leak:libOniFile.so\n"
         "leak:libPS1080.so\n"
         "leak:libPSLink.so\n"
         "leak:libdrm\n"
         "leak:libwayland\n"
         "leak:libX11\n"
         "leak:libxcb\n";
}
