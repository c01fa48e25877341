// The stabilizer's containers allocate through Bullet's allocator (btAlignedAlloc): an app that routes Bullet's
// memory through btAlignedAllocSetCustom (as engines do) gets the stabilizer's too, aligned for Eigen's fixed-size
// blocks. (Eigen's own sparse factorization, SparseLDLT, allocates through Eigen.)
#ifndef QUATHINGE_STABILIZER_BULLET_ALLOCATOR_H
#define QUATHINGE_STABILIZER_BULLET_ALLOCATOR_H

#include "LinearMath/btAlignedAllocator.h"

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

namespace quathinge
{
namespace stabilizer
{
/// A standard allocator over btAlignedAlloc/btAlignedFree, at least 16-byte aligned.
template <class T>
struct BulletAllocator
{
	using value_type = T;
	BulletAllocator() = default;
	template <class U>
	BulletAllocator(const BulletAllocator<U>&)
	{
	}
	T* allocate(std::size_t n)
	{
		const int alignment = int(alignof(T) > 16 ? alignof(T) : 16);
		void* p = btAlignedAlloc(n * sizeof(T), alignment);
#if defined(__cpp_exceptions)
		if (!p && n > 0) throw std::bad_alloc();
#else
		if (!p && n > 0) std::abort();  // as std::allocator without exceptions
#endif
		return static_cast<T*>(p);
	}
	void deallocate(T* p, std::size_t) { btAlignedFree(p); }
	template <class U>
	bool operator==(const BulletAllocator<U>&) const
	{
		return true;
	}
	template <class U>
	bool operator!=(const BulletAllocator<U>&) const
	{
		return false;
	}
};

/// The stabilizer's dynamic array: a std::vector through Bullet's allocator.
template <class T>
using Array = std::vector<T, BulletAllocator<T>>;
}  // namespace stabilizer
}  // namespace quathinge

#endif
