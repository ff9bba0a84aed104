#pragma once
// Counting replacements of the global operator new/delete, for allocation tests
// (tests/support/counting_allocator.cpp). Linking that file into a test binary replaces the
// global allocation functions of the whole binary: it must hold only allocation tests.
#include <cstddef>

namespace posefair::testing {

// Allocations (any replaceable operator new that returned memory) since the program started.
std::size_t allocations();
// Requested bytes allocated and not yet freed.
std::ptrdiff_t live_bytes();
// Allocations made by the calling thread since it started.
std::size_t thread_allocations();
// Stores p where the optimiser cannot see it unused, so that a test's allocation is not elided.
void keep(void* p);

// Counter slots: counts of one thread's allocations that outlive the thread (a thread_local
// counter does not), so a test can read them after joining threads it does not own, or
// race-free (relaxed atomics) while those threads run.
inline constexpr int kCounterSlots = 16;
// Claims the next free slot for the calling thread: from now on each of its allocations is
// also counted there. Does not allocate. Returns the slot, or -1 if all are taken.
int claim_counter_slot();
// Stops counting the calling thread's allocations into its slot, or counts them there again:
// for a thread that is real-time only for part of its work (a driver thread while it fairs).
void suspend_counter_slot();
void resume_counter_slot();
// Whether the calling thread has claimed a slot (suspended or not).
bool has_counter_slot();
// How many slots are claimed (at most kCounterSlots).
int counter_slots_claimed();
// Allocations counted in `slot` (0 for a slot out of range or not claimed).
std::size_t slot_allocations(int slot);
// Zeroes and frees every slot (and detaches the calling thread from its slot, if it has one).
// Call it only when no other thread that claimed a slot is still running, e.g. at the start
// of a test, when the threads of the previous one have been joined.
void release_counter_slots();

}  // namespace posefair::testing
