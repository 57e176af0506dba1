// fuzz_vdb's operator new: a request above 1 GiB throws std::bad_alloc, as
// it does in strahl where no such block exists (OpenVDB's zip and blosc
// readers allocate a buffer of a size read from the file, new char[n]);
// ASan's own operator new would abort the fuzzer there instead, although
// st_vdb.cpp turns bad_alloc into exit 2. Memory still goes through
// malloc/free, which ASan checks.
#include <cstdlib>
#include <new>

namespace {
void *get(std::size_t n) {
    if (n > (std::size_t{1} << 30)) throw std::bad_alloc();
    void *p = std::malloc(n ? n : 1);
    if (!p) throw std::bad_alloc();
    return p;
}
void *get_aligned(std::size_t n, std::align_val_t a) {
    if (n > (std::size_t{1} << 30)) throw std::bad_alloc();
    std::size_t al = static_cast<std::size_t>(a);
    void *p = std::aligned_alloc(al, (n + al - 1) / al * al ? (n + al - 1) / al * al : al);
    if (!p) throw std::bad_alloc();
    return p;
}
} // namespace

void *operator new(std::size_t n) {
    return get(n);
}
void *operator new[](std::size_t n) {
    return get(n);
}
void *operator new(std::size_t n, const std::nothrow_t &) noexcept {
    try {
        return get(n);
    } catch (...) {
        return nullptr;
    }
}
void *operator new[](std::size_t n, const std::nothrow_t &t) noexcept {
    return operator new(n, t);
}
void *operator new(std::size_t n, std::align_val_t a) {
    return get_aligned(n, a);
}
void *operator new[](std::size_t n, std::align_val_t a) {
    return get_aligned(n, a);
}
void operator delete(void *p) noexcept {
    std::free(p);
}
void operator delete[](void *p) noexcept {
    std::free(p);
}
void operator delete(void *p, std::size_t) noexcept {
    std::free(p);
}
void operator delete[](void *p, std::size_t) noexcept {
    std::free(p);
}
void operator delete(void *p, const std::nothrow_t &) noexcept {
    std::free(p);
}
void operator delete[](void *p, const std::nothrow_t &) noexcept {
    std::free(p);
}
void operator delete(void *p, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete[](void *p, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete(void *p, std::size_t, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete[](void *p, std::size_t, std::align_val_t) noexcept {
    std::free(p);
}
