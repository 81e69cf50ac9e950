// `drape bench error`.
#include "bench/report.hpp"

namespace drape::bench {

Result<void> run_error(const BenchOptions&) { return fail("error: not available in this build yet"); }

}  // namespace drape::bench
