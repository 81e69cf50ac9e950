// `drape bench stability`.
#include "bench/report.hpp"

namespace drape::bench {

Result<void> run_stability(const BenchOptions&) { return fail("stability: not available in this build yet"); }

}  // namespace drape::bench
