// `drape bench render`.
#include "bench/report.hpp"

namespace drape::bench {

Result<void> run_render(const BenchOptions&) { return fail("render: not available in this build yet"); }

}  // namespace drape::bench
