// Linked into every executable of a sanitizer build (TAMP_SANITIZE). Fast DDS 2.9 itself deletes
// its StatisticsReaderImpl through a base pointer of another size (RTPSReader::~RTPSReader, in
// libfastrtps): ASan's new-delete-type-mismatch check fires in Debian's library, not in our code.
// Every other check stays on. Applies to services started by the integration tests too.
extern "C" const char* __asan_default_options() { return "new_delete_type_mismatch=0"; }  // NOLINT
