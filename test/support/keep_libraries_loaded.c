/* Sanitized test runs only (scripts/test.sh --sanitize): Open MPI unloads its components with
 * dlclose in MPI_Finalize, after which LeakSanitizer can no longer name the library a leak came
 * from, and so cannot suppress the leaks Open MPI leaves at exit (scripts/sanitizers/lsan.supp).
 * Preloaded into the tests, this dlclose keeps every library loaded until the process ends. */
int dlclose(void* handle) {
  (void)handle;
  return 0;
}
