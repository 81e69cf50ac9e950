// `drape bench scale`.
#include "bench/report.hpp"

namespace drape::bench {

Result<void> run_scale(const BenchOptions&) { return fail("scale: not available in this build yet"); }

}  // namespace drape::bench
