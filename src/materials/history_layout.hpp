#pragma once
// Where each material's history variables live in a particle's history row: the union of the
// names declared by the materials of a case, and per material the slot of each name (or -1).
// Every particle has stride() values; a particle of material m keeps its model's variables in
// its model's order, the rest of the row unused.
#include <algorithm>
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "materials/material.hpp"

namespace rktsph {

class HistoryLayout {
 public:
  HistoryLayout() = default;
  explicit HistoryLayout(const std::vector<std::shared_ptr<const Material>>& materials) {
    for (const auto& m : materials) {
      stride_ = std::max(stride_, m->state_size());
      for (const auto& n : m->state_names()) {
        if (std::find(names_.begin(), names_.end(), n) == names_.end()) names_.push_back(n);
      }
    }
    for (const auto& m : materials) {
      std::vector<int> slots(names_.size(), -1);
      const auto own = m->state_names();
      for (std::size_t i = 0; i < names_.size(); ++i) {
        for (std::size_t j = 0; j < own.size(); ++j) {
          if (own[j] == names_[i]) slots[i] = static_cast<int>(j);
        }
      }
      slot_.push_back(std::move(slots));
    }
  }

  /// Values per particle (the largest state_size() of the materials).
  int stride() const { return stride_; }
  /// Union of the names, in first-declared order.
  const std::vector<std::string>& names() const { return names_; }
  /// Index of `name` in names(), or -1.
  int find(std::string_view name) const {
    for (std::size_t i = 0; i < names_.size(); ++i) {
      if (names_[i] == name) return static_cast<int>(i);
    }
    return -1;
  }
  /// Slot of names()[name_index] for material m, or -1 if that material lacks it.
  int slot(int material, std::size_t name_index) const { return slot_[static_cast<std::size_t>(material)][name_index]; }

 private:
  int stride_ = 0;
  std::vector<std::string> names_;
  std::vector<std::vector<int>> slot_;
};

}  // namespace rktsph
