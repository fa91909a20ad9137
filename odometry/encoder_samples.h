#pragma once
// What a replay consumes: one row per encoder interval (t(k-1), t(k)], holding the interval's
// length and the value of every encoder channel over it, for any number of channels. A channel
// is whatever the robot's model reads (model_interface.h): a wheel's mean rate over the interval
// (rad/s), or an angle such as a steering or castor pivot angle (rad, the mean of the readings at
// the interval's two ends). Rows are stored flat, [dt, v_0, ..., v_{C-1}] each, read front to
// back: for three channels a row is 32 bytes, as the replay's hot loop wants it.

#include <cassert>
#include <cstddef>
#include <initializer_list>
#include <iterator>
#include <memory>
#include <vector>

namespace fitcal {

inline constexpr int kMaxChannels = 16;

// A view of one row: `dt_s` and `value[0..C)`. Cheap to copy; points into the container.
template <typename D>
struct BasicSampleView {
  D& dt_s;
  D* value;
};
using SampleView = BasicSampleView<double>;
using ConstSampleView = BasicSampleView<const double>;

class EncoderSamples {
 public:
  explicit EncoderSamples(int num_channels = 3) : num_channels_(num_channels) {
    assert(num_channels >= 1 && num_channels <= kMaxChannels);
  }

  int num_channels() const { return num_channels_; }
  // Doubles per row: the interval length, then the channel values.
  int stride() const { return num_channels_ + 1; }
  std::size_t size() const { return Rows().size() / static_cast<std::size_t>(stride()); }
  bool empty() const { return Rows().empty(); }
  void reserve(std::size_t rows) {
    MutableRows().reserve(rows * static_cast<std::size_t>(stride()));
  }
  std::size_t capacity_rows() const {
    return Rows().capacity() / static_cast<std::size_t>(stride());
  }
  void clear() { MutableRows().clear(); }
  // Rows k >= n are dropped; new rows are zero.
  void resize(std::size_t rows) {
    MutableRows().resize(rows * static_cast<std::size_t>(stride()), 0.0);
  }

  // Appends a row; `values` holds num_channels() numbers.
  void push_back(double dt_s, const double* values) {
    std::vector<double>& rows = MutableRows();
    rows.push_back(dt_s);
    rows.insert(rows.end(), values, values + num_channels_);
  }
  void push_back(double dt_s, std::initializer_list<double> values) {
    assert(static_cast<int>(values.size()) == num_channels_);
    push_back(dt_s, values.begin());
  }
  void push_back(ConstSampleView row) { push_back(row.dt_s, row.value); }

  SampleView operator[](std::size_t k) { return {Row(k)[0], Row(k) + 1}; }
  ConstSampleView operator[](std::size_t k) const { return {Row(k)[0], Row(k) + 1}; }
  SampleView back() { return (*this)[size() - 1]; }
  ConstSampleView back() const { return (*this)[size() - 1]; }

  // The flat rows, for kernels that walk them with stride().
  const double* data() const { return Rows().data(); }
  double* data() { return MutableRows().data(); }

  bool operator==(const EncoderSamples& o) const {
    return num_channels_ == o.num_channels_ && Rows() == o.Rows();
  }

  // Iteration yields row views (`for (auto&& s : samples) s.value[0] *= 2;`).
  template <typename Owner, typename View>
  class Iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = View;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = View;
    Iterator(Owner* owner, std::size_t k) : owner_(owner), k_(k) {}
    View operator*() const { return (*owner_)[k_]; }
    Iterator& operator++() {
      ++k_;
      return *this;
    }
    bool operator!=(const Iterator& o) const { return k_ != o.k_; }
    bool operator==(const Iterator& o) const { return k_ == o.k_; }

   private:
    Owner* owner_;
    std::size_t k_;
  };
  using iterator = Iterator<EncoderSamples, SampleView>;
  using const_iterator = Iterator<const EncoderSamples, ConstSampleView>;
  iterator begin() { return {this, 0}; }
  iterator end() { return {this, size()}; }
  const_iterator begin() const { return {this, 0}; }
  const_iterator end() const { return {this, size()}; }

 private:
  // The rows are shared by copies until one of them is changed (copy on write): a run's samples
  // are copied into every fold and half of the choices by transfer, and read only there.
  const std::vector<double>& Rows() const {
    static const std::vector<double> kNoRows;
    return rows_ ? *rows_ : kNoRows;
  }
  std::vector<double>& MutableRows() {
    if (!rows_) {
      rows_ = std::make_shared<std::vector<double>>();
    } else if (rows_.use_count() > 1) {
      rows_ = std::make_shared<std::vector<double>>(*rows_);
    }
    return *rows_;
  }
  double* Row(std::size_t k) {
    return MutableRows().data() + k * static_cast<std::size_t>(stride());
  }
  const double* Row(std::size_t k) const {
    return Rows().data() + k * static_cast<std::size_t>(stride());
  }

  int num_channels_;
  std::shared_ptr<std::vector<double>> rows_;
};

}  // namespace fitcal
