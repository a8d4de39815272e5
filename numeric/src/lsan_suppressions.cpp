// Sanitizer builds only: CLN (GiNaC's number library) allocates 26 bytes at static
// initialisation and never frees them. That is not ours; LeakSanitizer is told to skip it.
extern "C" const char* __lsan_default_suppressions() { return "leak:libcln.so\n"; }
