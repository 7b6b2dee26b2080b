#include "engine/util/kept_memory.h"

#include <algorithm>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace lancer {

bool keepFreedMemory(size_t trimBytes) {
#if defined(__GLIBC__) && defined(M_MMAP_THRESHOLD) && defined(M_TRIM_THRESHOLD)
    // A fixed mmap threshold also stops glibc from moving it block by block.
    return mallopt(M_MMAP_THRESHOLD, int(kKeptBlockBytes)) == 1 &&
           mallopt(M_TRIM_THRESHOLD, int(std::min<size_t>(trimBytes, size_t(1) << 30))) == 1;
#else
    (void)trimBytes;
    return false;
#endif
}

}  // namespace lancer
