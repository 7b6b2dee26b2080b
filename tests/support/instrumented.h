// Bounds on wall time in tests that the sanitized runs of scripts/test also build.
#pragma once

namespace lancer::test {

/// How many times slower instrumented code runs (AddressSanitizer or ThreadSanitizer): the same
/// work takes 2 to 15 times longer, so a bound on wall time scales with it.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr double kInstrumented = 10.0;
#else
inline constexpr double kInstrumented = 1.0;
#endif

}  // namespace lancer::test
