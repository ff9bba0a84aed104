#include "posefair/daemon/subscriber_table.hpp"

#include <algorithm>

#include "posefair/daemon/address_allow_list.hpp"

namespace posefair::daemon {

bool Subscriber::carries(std::uint32_t stream) const {
  if (stream_count == 0) return true;
  for (std::size_t i = 0; i < stream_count; ++i)
    if (streams[i] == stream) return true;
  return false;
}

SubscriberTable::SubscriberTable(std::size_t capacity, std::size_t per_address)
    : slots_(capacity), used_(capacity, 0), sent_(new std::atomic<std::uint64_t>[capacity]), per_address_(per_address) {
  for (std::size_t i = 0; i < capacity; ++i) sent_[i].store(0, std::memory_order_relaxed);
  for (const OutputEncoderEntry* e : output_encoder_entries())
    encoders_.push_back(offered_to_subscribers(*e) ? e->make({}, {}) : nullptr);
}

SubscriberTable::Outcome SubscriberTable::subscribe(const Subscriber& s) {
  std::lock_guard lock(mutex_);
  const AddressBytes host = address_bytes(s.address);
  std::size_t same_host = 0;
  std::size_t free_slot = slots_.size();
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (!used_[i]) {
      free_slot = std::min(free_slot, i);
      continue;
    }
    Subscriber& e = slots_[i];
    if (e.address == s.address) {
      if (s.last_request_id <= e.last_request_id) return Outcome::Replayed;
      const std::int64_t since = e.since_ns;
      e = s;
      e.since_ns = since;
      generation_.fetch_add(1, std::memory_order_release);
      return Outcome::Renewed;
    }
    const AddressBytes other = address_bytes(e.address);
    if (other.family == host.family && other.bytes == host.bytes) ++same_host;
  }
  if (same_host >= per_address_) return Outcome::AddressFull;
  if (free_slot == slots_.size()) return Outcome::TableFull;
  slots_[free_slot] = s;
  used_[free_slot] = 1;
  sent_[free_slot].store(0, std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);
  return Outcome::Added;
}

bool SubscriberTable::unsubscribe(const Endpoint& address, std::uint32_t request_id) {
  std::lock_guard lock(mutex_);
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (!used_[i] || !(slots_[i].address == address)) continue;
    if (request_id <= slots_[i].last_request_id) return false;
    used_[i] = 0;
    generation_.fetch_add(1, std::memory_order_release);
    return true;
  }
  return false;
}

std::size_t SubscriberTable::expire(std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  std::size_t n = 0;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (used_[i] && slots_[i].expires_ns <= now_ns) {
      used_[i] = 0;
      ++n;
    }
  }
  if (n) generation_.fetch_add(1, std::memory_order_release);
  return n;
}

std::vector<SubscriberTable::Listed> SubscriberTable::list() const {
  std::lock_guard lock(mutex_);
  std::vector<Listed> out;
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (used_[i]) out.push_back({slots_[i], sent_[i].load(std::memory_order_relaxed)});
  return out;
}

std::size_t SubscriberTable::size() const {
  std::lock_guard lock(mutex_);
  return static_cast<std::size_t>(std::count(used_.begin(), used_.end(), 1));
}

// Filled under the lock, waiting for it: this runs before the publisher's first pose, so a
// subscriber already in the table is sent that pose even when the control thread holds the
// lock then (a view that refresh() had to fill would miss poses until the lock was free).
SubscriberTable::View SubscriberTable::make_view() const {
  View v;
  v.entries.resize(slots_.size());
  v.slot.resize(slots_.size());
  const std::lock_guard lock(mutex_);
  copy_locked(v);
  return v;
}

void SubscriberTable::refresh(View& v) const {
  const std::uint64_t g = generation_.load(std::memory_order_acquire);
  if (g == v.generation) return;
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;  // the control thread is changing it: next pose
  copy_locked(v);
}

void SubscriberTable::copy_locked(View& v) const {
  v.count = 0;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (!used_[i]) continue;
    v.entries[v.count] = slots_[i];
    v.slot[v.count] = static_cast<std::uint32_t>(i);
    ++v.count;
  }
  v.generation = generation_.load(std::memory_order_relaxed);
}

}  // namespace posefair::daemon
