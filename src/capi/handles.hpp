// Generation-counted handles of the C API (issue 19, item 12; docs/c_api.md, "Handles").
//
// A gmasim_model* or gmasim_sim* that the C API hands out is not the address of an object: it
// encodes a slot of a table, the slot's generation when the handle was made, and the handle's
// type. Freeing a handle bumps its slot's generation, so a freed handle (a double free, a use
// after free), a handle of the other type or any other pointer value is recognised as "not a
// live handle" and refused with GMASIM_E_ARGUMENT: nothing is read through it, so the sanitizer
// build has nothing to flag and glibc's allocator never sees a double free.
//
// Layout of a handle value (64-bit pointers): generation (32 bits) | type tag (4 bits) |
// slot + 1 (28 bits). Slots live in chunks of kChunk that are allocated once and never freed
// (a stale handle always finds valid memory); up to kChunks * kChunk handles may be live at
// once. A slot's generation wraps after 2^32 frees of that slot: a handle freed 2^32 frees ago
// of the same slot would be taken for the live one (documented; far beyond any use).
//
// Threads: add() and remove() take a mutex (they allocate anyway); get() is lock-free and
// allocation-free (two atomic loads), so gmasim_sim_step stays real-time. Freeing a handle
// while another thread uses the same handle is the caller's race, as for any C object.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <new>
#include <vector>

namespace gmasim::capi_detail {

static_assert(sizeof(std::uintptr_t) >= 8, "the C API's handle encoding needs 64-bit pointers");

template <class T, unsigned Tag>
class HandleTable {
 public:
  static constexpr std::uint64_t kSlotBits = 28, kTagBits = 4;
  static constexpr std::size_t kChunk = 1024, kChunks = 4096;  // 4 Mi live handles at most
  static_assert(Tag > 0 && Tag < (1u << kTagBits));
  static_assert(kChunk * kChunks < (std::uint64_t{1} << kSlotBits));

  // Takes ownership of `object` and returns its handle value. Throws std::bad_alloc when the
  // table is full or a chunk cannot be allocated (object is then destroyed).
  std::uintptr_t add(std::unique_ptr<T> object) {
    const std::lock_guard<std::mutex> lock(mu_);
    std::size_t index;
    if (!free_.empty()) {
      index = free_.back();
      free_.pop_back();
    } else {
      if (next_ == kChunk * kChunks) throw std::bad_alloc();
      index = next_;
      Slot*& chunk = chunk_storage_[index / kChunk];
      if (!chunk) {
        chunk = new Slot[kChunk];  // never freed: stale handles must find valid memory
        chunks_[index / kChunk].store(chunk, std::memory_order_release);
      }
      ++next_;
    }
    Slot& s = slot(index);
    const std::uint32_t gen = s.generation.load(std::memory_order_relaxed);
    s.object.store(object.release(), std::memory_order_release);
    return encode(index, gen);
  }

  // The live object of a handle value, or nullptr (0, freed, of the other type, or unknown).
  T* get(std::uintptr_t handle) const noexcept {
    std::size_t index = 0;
    std::uint32_t gen = 0;
    if (!decode(handle, index, gen)) return nullptr;
    const Slot* chunk = chunks_[index / kChunk].load(std::memory_order_acquire);
    if (!chunk) return nullptr;
    const Slot& s = chunk[index % kChunk];
    if (s.generation.load(std::memory_order_acquire) != gen) return nullptr;
    return s.object.load(std::memory_order_acquire);
  }

  // Destroys the handle's object; false (nothing done) if the handle is not live.
  bool remove(std::uintptr_t handle) noexcept {
    std::unique_ptr<T> doomed;
    {
      const std::lock_guard<std::mutex> lock(mu_);
      std::size_t index = 0;
      std::uint32_t gen = 0;
      if (!decode(handle, index, gen) || index >= next_) return false;
      Slot& s = slot(index);
      if (s.generation.load(std::memory_order_relaxed) != gen) return false;
      T* obj = s.object.exchange(nullptr, std::memory_order_acq_rel);
      if (!obj) return false;
      s.generation.store(gen + 1, std::memory_order_release);
      doomed.reset(obj);
      try {
        free_.push_back(index);
      } catch (...) {
        // The slot is lost for reuse (no memory to remember it), the handle is still dead.
      }
    }
    return true;  // the object is destroyed outside the lock
  }

 private:
  struct Slot {
    std::atomic<std::uint32_t> generation{1};
    std::atomic<T*> object{nullptr};
  };

  static std::uintptr_t encode(std::size_t index, std::uint32_t gen) {
    return static_cast<std::uintptr_t>((std::uint64_t{gen} << (kSlotBits + kTagBits)) |
                                       (std::uint64_t{Tag} << kSlotBits) | (index + 1));
  }
  static bool decode(std::uintptr_t h, std::size_t& index, std::uint32_t& gen) {
    const std::uint64_t v = h;
    const std::uint64_t slot_plus_1 = v & ((std::uint64_t{1} << kSlotBits) - 1);
    const std::uint64_t tag = (v >> kSlotBits) & ((std::uint64_t{1} << kTagBits) - 1);
    if (tag != Tag || slot_plus_1 == 0 || slot_plus_1 > kChunk * kChunks) return false;
    index = static_cast<std::size_t>(slot_plus_1 - 1);
    gen = static_cast<std::uint32_t>(v >> (kSlotBits + kTagBits));
    return true;
  }
  Slot& slot(std::size_t index) { return chunk_storage_[index / kChunk][index % kChunk]; }

  std::array<std::atomic<Slot*>, kChunks> chunks_{};  // read by get() without the lock
  std::array<Slot*, kChunks> chunk_storage_{};        // the same pointers, under the lock
  std::mutex mu_;
  std::vector<std::size_t> free_;  // slots to reuse (their generation already bumped)
  std::size_t next_ = 0;           // slots ever used
};

}  // namespace gmasim::capi_detail
