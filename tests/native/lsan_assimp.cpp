// assimp (a system library, not built here) leaks some of what it allocates for a few malformed
// FBX files before it gives up on them: those leaks are assimp's, outside the import's code, and
// LeakSanitizer leaves them out in the test binaries that hand such files to it. In builds
// without the sanitizer nothing calls this.
extern "C" const char* __lsan_default_suppressions() { return "leak:libassimp.so\n"; }
