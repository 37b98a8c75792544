// Values made once per key and wavelength and shared by the render's threads: the mapped-pupil
// table's nodes (MappedPupilTable::node) and the footprints' light images
// (FootprintScatter::light_image). Each is costly to make (rays traced through the lens, a mesh
// deposited) and looked up many times a footprint, from every thread.
//
// A map under a reader-writer lock holds them; in front of it each thread keeps direct-mapped slots
// of the values it used last (ThreadSlots, e.g. in its scratch space), so that most lookups take no
// lock: with too few slots two threads spent 10 % of an exact 1080p render in the lock (the two
// users' constants say how many they keep). A value missing from the map is made outside the lock;
// another thread may make the same one meanwhile, and the first kept wins.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <unordered_map>
#include <utility>
#include <vector>

namespace lensmith::render_detail {

template <typename Value>
class SharedMemo {
 public:
  // A thread's recent values. It must not outlive the memo, and must forget() when the memo is cleared.
  struct ThreadSlots {
    struct Slot {
      std::uint64_t key = ~std::uint64_t{0};
      double wavelength_nm = 0.0;
      const Value* value = nullptr;
    };
    std::vector<Slot> slots;
    void forget() { std::fill(slots.begin(), slots.end(), Slot{}); }
  };

  // 2^slot_bits slots for each thread.
  explicit SharedMemo(int slot_bits) : slot_bits_(slot_bits) {}

  // The value of (key, wavelength_nm): the thread's slot's, the map's, or make()'s (a Value). Where
  // also_key(value) names another key (std::optional<std::uint64_t>), the value made is kept under
  // that key too (for the same wavelength), unless that one has a value already.
  template <typename Make, typename AlsoKey>
  const Value& get(std::uint64_t key, double wavelength_nm, ThreadSlots& local, Make&& make, AlsoKey&& also_key) const {
    if (local.slots.empty()) local.slots.resize(std::size_t{1} << slot_bits_);
    std::uint64_t bits = 0;
    std::memcpy(&bits, &wavelength_nm, sizeof bits);
    typename ThreadSlots::Slot& slot = local.slots[(key * 0x9E3779B97F4A7C15ull ^ bits) >> (64 - slot_bits_)];
    if (slot.key == key && slot.wavelength_nm == wavelength_nm) return *slot.value;
    const std::pair<std::uint64_t, double> k{key, wavelength_nm};
    const Value* found = nullptr;
    {
      std::shared_lock lock(mutex_);
      if (auto it = values_.find(k); it != values_.end()) found = it->second.get();
    }
    if (found == nullptr) {
      auto made = std::make_shared<const Value>(make());
      const std::optional<std::uint64_t> other = also_key(*made);
      std::unique_lock lock(mutex_);
      auto [it, inserted] = values_.try_emplace(k, made);
      if (inserted) {
        ++made_;
        if (other) values_.try_emplace({*other, wavelength_nm}, made);
      }
      found = it->second.get();
    }
    slot = {key, wavelength_nm, found};
    return *found;
  }
  template <typename Make>
  const Value& get(std::uint64_t key, double wavelength_nm, ThreadSlots& local, Make&& make) const {
    return get(key, wavelength_nm, local, std::forward<Make>(make), [](const Value&) { return std::optional<std::uint64_t>{}; });
  }

  // Values made so far, kept or cleared.
  std::size_t made() const { return made_.load(); }
  // Every value freed (each thread's slots must forget them).
  void clear() const {
    std::unique_lock lock(mutex_);
    values_.clear();
  }

 private:
  struct KeyHash {
    std::size_t operator()(const std::pair<std::uint64_t, double>& k) const {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &k.second, sizeof bits);
      return std::hash<std::uint64_t>{}(k.first * 0x9E3779B97F4A7C15ull ^ bits);
    }
  };
  int slot_bits_;
  mutable std::shared_mutex mutex_;
  mutable std::unordered_map<std::pair<std::uint64_t, double>, std::shared_ptr<const Value>, KeyHash> values_;
  mutable std::atomic<std::size_t> made_{0};
};

}  // namespace lensmith::render_detail
