#include "correction/bilinear_remap.h"

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdint>
#include <cstring>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define OMNICAL_REMAP_AVX2 1
#endif

namespace omnical {

namespace {

// Everything here serves the AVX2 path; elsewhere RemapLinear is cv::remap (and unused
// helpers would stop a -Werror build).
#ifdef OMNICAL_REMAP_AVX2
// OpenCV's fixed-point maps hold fractions in 1/32 px (INTER_TAB_SIZE). Its bilinear
// weights are the products of two such fractions in 1/32768 (each an exact multiple of 32,
// since the products are multiples of 1/1024), so (sum + 2^14) >> 15 over them equals
// (sum + 2^9) >> 10 over the products in 1/1024. The one exception, fraction (0, 0),
// where OpenCV stores 32767 and 1 instead of 32768 and 0, rounds to the same byte too.
// tests/bilinear_remap_test.cc checks every fraction against cv::remap.
constexpr int kFractionSteps = 32;
constexpr int kWeightShift = 10;

// The frame's bytes at tap (x, y), 0 outside it (BORDER_CONSTANT with value 0).
inline int TapOrZero(const uint8_t* frame, size_t step, int cols, int rows, int x, int y, int channel) {
  if (x < 0 || x >= cols || y < 0 || y >= rows) return 0;
  return frame[static_cast<size_t>(y) * step + 3 * static_cast<size_t>(x) + channel];
}

// Any pixel, borders included: what cv::remap computes for it.
inline void RemapPixel(const uint8_t* frame, size_t step, int cols, int rows, int x, int y, int fraction_index,
                       uint8_t* out) {
  const int fx = fraction_index % kFractionSteps, fy = (fraction_index / kFractionSteps) % kFractionSteps;
  const int w00 = (kFractionSteps - fx) * (kFractionSteps - fy), w01 = fx * (kFractionSteps - fy);
  const int w10 = (kFractionSteps - fx) * fy, w11 = fx * fy;
  for (int channel = 0; channel < 3; ++channel) {
    const int sum = w00 * TapOrZero(frame, step, cols, rows, x, y, channel) +
                    w01 * TapOrZero(frame, step, cols, rows, x + 1, y, channel) +
                    w10 * TapOrZero(frame, step, cols, rows, x, y + 1, channel) +
                    w11 * TapOrZero(frame, step, cols, rows, x + 1, y + 1, channel);
    out[channel] = static_cast<uint8_t>((sum + (1 << (kWeightShift - 1))) >> kWeightShift);
  }
}

struct RowInput {
  const uint8_t* frame;
  size_t step;
  int cols, rows;
  const int16_t* source_xy;  // map1's row: x, y of each pixel's top-left tap
  const uint16_t* fraction;  // map2's row
  int width;
};

// Pixels [from, to) of the row one by one.
void RemapPixelsAnywhere(const RowInput& in, int from, int to, uint8_t* out) {
  for (int u = from; u < to; ++u)
    RemapPixel(in.frame, in.step, in.cols, in.rows, in.source_xy[2 * u], in.source_xy[2 * u + 1], in.fraction[u],
               out + 3 * u);
}

// Four pixels whose two taps rows each have 8 readable bytes at the top-left tap:
// `top`/`bottom` hold those 8 bytes per 64-bit lane, `fractions` fx in byte 0 and fy in
// byte 1 of each lane. Returns the pixels as 16-bit [R G B 0] x 4, ordered [0 1 | 2 3].
__attribute__((target("avx2"))) inline __m256i BlendFour(__m256i top, __m256i bottom, __m256i fractions) {
  // Each row's left and right taps side by side per channel, [L R L R L R 0 0] per lane,
  // so one multiply-add of unsigned bytes by small signed weights interpolates along x.
  const __m256i pair_taps = _mm256_setr_epi8(0, 3, 1, 4, 2, 5, -1, -1, 8, 11, 9, 12, 10, 13, -1, -1, 0, 3, 1, 4, 2,
                                             5, -1, -1, 8, 11, 9, 12, 10, 13, -1, -1);
  const __m256i fx_at_left = _mm256_setr_epi8(0, -1, 0, -1, 0, -1, -1, -1, 8, -1, 8, -1, 8, -1, -1, -1, 0, -1, 0, -1,
                                              0, -1, -1, -1, 8, -1, 8, -1, 8, -1, -1, -1);
  const __m256i fx_at_right = _mm256_setr_epi8(-1, 0, -1, 0, -1, 0, -1, -1, -1, 8, -1, 8, -1, 8, -1, -1, -1, 0, -1,
                                               0, -1, 0, -1, -1, -1, 8, -1, 8, -1, 8, -1, -1);
  const __m256i steps_at_left = _mm256_setr_epi8(32, 0, 32, 0, 32, 0, 0, 0, 32, 0, 32, 0, 32, 0, 0, 0, 32, 0, 32, 0,
                                                 32, 0, 0, 0, 32, 0, 32, 0, 32, 0, 0, 0);
  // fy of the lane's first / second pixel as 16-bit words.
  const __m256i fy_first = _mm256_setr_epi8(1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1,
                                            -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1);
  const __m256i fy_second = _mm256_setr_epi8(9, -1, 9, -1, 9, -1, 9, -1, 9, -1, 9, -1, 9, -1, 9, -1, 9, -1, 9, -1, 9,
                                             -1, 9, -1, 9, -1, 9, -1, 9, -1, 9, -1);
  const __m256i steps = _mm256_set1_epi16(kFractionSteps);
  const __m256i half = _mm256_set1_epi32(1 << (kWeightShift - 1));

  // (32 - fx, fx) per channel pair; at most 32 * 255 per product sum, no saturation.
  const __m256i weights_x = _mm256_add_epi8(_mm256_sub_epi8(steps_at_left, _mm256_shuffle_epi8(fractions, fx_at_left)),
                                            _mm256_shuffle_epi8(fractions, fx_at_right));
  const __m256i along_top = _mm256_maddubs_epi16(_mm256_shuffle_epi8(top, pair_taps), weights_x);
  const __m256i along_bottom = _mm256_maddubs_epi16(_mm256_shuffle_epi8(bottom, pair_taps), weights_x);
  // (32 - fy, fy) per top/bottom word pair, 32-bit sums.
  const __m256i fy_a = _mm256_shuffle_epi8(fractions, fy_first), fy_b = _mm256_shuffle_epi8(fractions, fy_second);
  const __m256i weights_a = _mm256_blend_epi16(_mm256_sub_epi16(steps, fy_a), fy_a, 0xAA);
  const __m256i weights_b = _mm256_blend_epi16(_mm256_sub_epi16(steps, fy_b), fy_b, 0xAA);
  const __m256i first = _mm256_madd_epi16(_mm256_unpacklo_epi16(along_top, along_bottom), weights_a);
  const __m256i second = _mm256_madd_epi16(_mm256_unpackhi_epi16(along_top, along_bottom), weights_b);
  return _mm256_packus_epi32(_mm256_srli_epi32(_mm256_add_epi32(first, half), kWeightShift),
                             _mm256_srli_epi32(_mm256_add_epi32(second, half), kWeightShift));
}

__attribute__((target("avx2"))) inline __m256i LoadFourRows(const uint8_t* frame, const int32_t* offset) {
  int64_t bytes[4];
  for (int k = 0; k < 4; ++k) std::memcpy(&bytes[k], frame + offset[k], 8);
  return _mm256_setr_epi64x(bytes[0], bytes[1], bytes[2], bytes[3]);
}

// Eight pixels at a time where all their taps are inside the frame (and 8 bytes can be
// read from each tap row: x <= cols - 3), the rest one by one. Scalar loads into the
// vector beat AVX2 gathers on the CPUs measured.
__attribute__((target("avx2"))) void RemapRowAvx2(const RowInput& in, uint8_t* out) {
  // (x, y) -> byte offset 3 x + step y in one multiply-add (step <= 32767, checked).
  const __m256i to_offset = _mm256_set1_epi32(static_cast<int32_t>((in.step << 16) | 3u));
  const __m256i fast_limit = _mm256_set1_epi32(((in.rows - 1) << 16) | ((in.cols - 2) & 0xffff));
  const __m256i minus_one = _mm256_set1_epi16(-1);
  const __m128i fraction_mask = _mm_set1_epi16(kFractionSteps - 1);
  const __m256i to_bytes = _mm256_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1, 0, 1, 2, 4, 5, 6,
                                            8, 9, 10, 12, 13, 14, -1, -1, -1, -1);
  const __m256i close_gap = _mm256_setr_epi32(0, 1, 2, 4, 5, 6, 7, 7);
  int u = 0;
  for (; u + 8 <= in.width && in.cols >= 3 && in.rows >= 2; u += 8) {
    const __m256i xy = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in.source_xy + 2 * u));
    const __m256i inside = _mm256_and_si256(_mm256_cmpgt_epi16(fast_limit, xy), _mm256_cmpgt_epi16(xy, minus_one));
    if (_mm256_movemask_epi8(inside) != -1) {
      RemapPixelsAnywhere(in, u, u + 8, out);
      continue;
    }
    alignas(32) int32_t offset[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(offset), _mm256_madd_epi16(xy, to_offset));
    // fx | fy << 8 per pixel, as 16-bit words.
    const __m128i index = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in.fraction + u));
    const __m128i fxy = _mm_or_si128(_mm_and_si128(index, fraction_mask),
                                     _mm_slli_epi16(_mm_and_si128(_mm_srli_epi16(index, 5), fraction_mask), 8));
    const __m256i pixels_0123 =
        BlendFour(LoadFourRows(in.frame, offset), LoadFourRows(in.frame + in.step, offset), _mm256_cvtepu16_epi64(fxy));
    const __m256i pixels_4567 = BlendFour(LoadFourRows(in.frame, offset + 4), LoadFourRows(in.frame + in.step, offset + 4),
                                          _mm256_cvtepu16_epi64(_mm_srli_si128(fxy, 8)));
    // Bytes [0 1 4 5 | 2 3 6 7] -> [0 1 2 3 | 4 5 6 7], 3 per pixel, 24 contiguous.
    __m256i bytes = _mm256_permute4x64_epi64(_mm256_packus_epi16(pixels_0123, pixels_4567), 0xD8);
    bytes = _mm256_permutevar8x32_epi32(_mm256_shuffle_epi8(bytes, to_bytes), close_gap);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 3 * u), _mm256_castsi256_si128(bytes));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + 3 * u + 16), _mm256_extracti128_si256(bytes, 1));
  }
  RemapPixelsAnywhere(in, u, in.width, out);
}

bool CpuHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}
#endif

}  // namespace

bool RemapLinearHasFastPath(const cv::Mat& frame, const cv::Mat& map1, const cv::Mat& map2) {
#ifdef OMNICAL_REMAP_AVX2
  return CpuHasAvx2() && frame.dims == 2 && map1.dims == 2 && map2.dims == 2 && frame.type() == CV_8UC3 &&
         !frame.empty() && frame.step[0] <= 32767 &&
         frame.rows <= 32767 && frame.cols <= 32767 && map1.type() == CV_16SC2 && map2.type() == CV_16UC1 &&
         map1.size() == map2.size() && !map1.empty();
#else
  (void)frame, (void)map1, (void)map2;
  return false;
#endif
}

void RemapLinear(const cv::Mat& frame, const cv::Mat& map1, const cv::Mat& map2, cv::Mat* out) {
#ifdef OMNICAL_REMAP_AVX2
  if (RemapLinearHasFastPath(frame, map1, map2)) {
    // Writing into the frame's own pixels would change taps still to be read.
    const cv::Mat source = out->data == frame.data ? frame.clone() : frame;
    out->create(map1.size(), CV_8UC3);
    cv::Mat& destination = *out;
    cv::parallel_for_(
        cv::Range(0, map1.rows),
        [&](const cv::Range& rows) {
          for (int v = rows.start; v < rows.end; ++v) {
            const RowInput in{source.data, source.step[0], source.cols, source.rows,
                              map1.ptr<int16_t>(v), map2.ptr<uint16_t>(v), map1.cols};
            RemapRowAvx2(in, destination.ptr<uint8_t>(v));
          }
        },
        static_cast<double>(map1.total()) / (1 << 16));  // cv::remap's stripes
    return;
  }
#endif
  cv::remap(frame, *out, map1, map2, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
}

}  // namespace omnical
