// Whether this build runs under AddressSanitizer (the asan and fuzz
// presets): code that pools or leaves memory on purpose does not then, so
// that ASan sees every block and its leak check stays meaningful.
#pragma once

namespace swarmsim {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

}  // namespace swarmsim
