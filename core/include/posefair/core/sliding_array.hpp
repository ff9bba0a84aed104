#pragma once
// The window's per-sample storage: `capacity` contiguous elements that slide by dropping the
// oldest ones in O(1). It holds twice the capacity and moves the live elements back to the
// front only when the view has slid a whole capacity along, so a push costs one element's
// move on average instead of the window's (at W = 128 that shift was most of a sample's cost).
// Index 0 is the oldest; a view of `capacity` elements is always contiguous, for spans.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace posefair {

template <class T>
class SlidingArray {
 public:
  void resize(std::size_t capacity) {
    capacity_ = capacity;
    base_ = 0;
    storage_.resize(2 * capacity);  // every element is written before it is read
  }
  void assign(std::size_t capacity, const T& value) {
    capacity_ = capacity;
    base_ = 0;
    storage_.assign(2 * capacity, value);
  }

  T& operator[](std::size_t i) { return storage_[base_ + i]; }
  const T& operator[](std::size_t i) const { return storage_[base_ + i]; }
  // A contiguous range over the capacity-long view (what std::span(array) sees).
  T* data() { return storage_.data() + base_; }
  const T* data() const { return storage_.data() + base_; }
  std::size_t size() const { return capacity_; }
  T* begin() { return data(); }
  T* end() { return data() + capacity_; }
  const T* begin() const { return data(); }
  const T* end() const { return data() + capacity_; }
  // Bytes of storage, for memory accounting.
  std::size_t capacity() const { return storage_.capacity(); }

  // Drops the oldest `count` of the `live` elements in use.
  void drop_front(std::size_t count, std::size_t live) {
    base_ += count;
    if (base_ > capacity_) {
      std::move(storage_.begin() + static_cast<std::ptrdiff_t>(base_), storage_.begin() + static_cast<std::ptrdiff_t>(base_ + live - count),
                storage_.begin());
      base_ = 0;
    }
  }

 private:
  std::vector<T> storage_;
  std::size_t capacity_ = 0, base_ = 0;
};

}  // namespace posefair
