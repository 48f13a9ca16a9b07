#include "segmesh_io/detail/dicom_file_check.hpp"

#include <gdcmDicts.h>
#include <gdcmGlobal.h>
#include <gdcmTag.h>
#include <gdcmVR.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/mapped_file.hpp"
#include "segmesh_io/detail/text.hpp"

namespace segmesh::volume_io {

namespace {

constexpr uint32_t kUndefined = 0xFFFFFFFFu;
constexpr int kMaxDepth = 32;

std::string tag_text(uint16_t group, uint16_t element) {
  char text[16];
  std::snprintf(text, sizeof text, "(%04x,%04x)", unsigned(group), unsigned(element));
  return text;
}

// The value representations of DICOM PS3.5 (2023). GDCM reads an unknown VR as one with a 32-bit
// length, so two letters of text become a length of a gigabyte or more, which it allocates and
// fills (found by fuzz_dicom): anything else is refused here.
bool is_known_vr(const char* vr) {
  static const char* const known[] = {"AE", "AS", "AT", "CS", "DA", "DS", "DT", "FD", "FL",
                                      "IS", "LO", "LT", "OB", "OD", "OF", "OL", "OV", "OW",
                                      "PN", "SH", "SL", "SQ", "SS", "ST", "SV", "TM", "UC",
                                      "UI", "UL", "UN", "UR", "US", "UT", "UV"};
  for (const char* v : known) {
    if (vr[0] == v[0] && vr[1] == v[1]) return true;
  }
  return false;
}

// GDCM reads many elements of an image (ImagePositionPatient, PixelSpacing, RescaleSlope, ...) as
// typed attributes (gdcm::Attribute) and asserts (aborts the process) when the file's VR is not
// compatible with the one its dictionary gives the element (fuzz_dicom: ImagePositionPatient
// stored as CS). Which elements it reads that way depends on the kind of image, so every public
// element of an explicit-VR file must carry its dictionary VR, or UN, by GDCM's own rule
// (gdcm::VR::Compatible); elements the dictionary does not know, and private ones, may carry any
// known VR. Returns why not, or "".
std::string dictionary_vr_mismatch(uint16_t group, uint16_t element, const char* vr) {
  if (group % 2 == 1) return {};
  const gdcm::VR expected =
      gdcm::Global::GetInstance().GetDicts().GetDictEntry(gdcm::Tag(group, element)).GetVR();
  if (expected == gdcm::VR::INVALID) return {};
  const std::string found(vr, 2);
  if (expected.Compatible(gdcm::VR(gdcm::VR::GetVRType(found.c_str())))) return {};
  std::ostringstream what;
  what << "element " << tag_text(group, element) << " has the value representation " << found
       << " where the DICOM dictionary gives " << expected;
  return what.str();
}

bool is_long_vr(const char* vr) {
  static const char* const long_vrs[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                         "SV", "UC", "UN", "UR", "UT", "UV"};
  for (const char* v : long_vrs) {
    if (vr[0] == v[0] && vr[1] == v[1]) return true;
  }
  return false;
}

// Walks data elements; records the image attributes of the top-level data set.
struct Walker {
  const unsigned char* bytes;
  size_t size;
  bool explicit_vr = true;
  bool big_endian = false;
  std::string error;

  int64_t rows = -1, columns = -1, bits_allocated = -1, samples = 1, frames = 1;
  int64_t bits_stored = -1, high_bit = -1, pixel_representation = 0;
  std::string format_error;
  std::string vr_error;  // the first element whose VR contradicts the dictionary
  bool pixel_data = false;
  bool pixel_encapsulated = false;
  uint64_t pixel_length = 0;

  uint16_t u16(size_t at, bool big) const {
    return big ? load_be<uint16_t>(bytes + at) : load_le<uint16_t>(bytes + at);
  }
  uint32_t u32(size_t at, bool big) const {
    return big ? load_be<uint32_t>(bytes + at) : load_le<uint32_t>(bytes + at);
  }

  bool fail(const std::string& what) {
    if (error.empty()) error = what;
    return false;
  }
  bool truncated(uint16_t group, uint16_t element, uint64_t needed, uint64_t left) {
    return fail("truncated: element " + tag_text(group, element) + " needs " +
                std::to_string(needed) + " bytes where " + std::to_string(left) + " remain");
  }

  // The elements in [pos, end). With `item`, stops after an item delimitation item (and fails
  // without one); otherwise stops at `end`.
  bool data_set(size_t& pos, size_t end, bool item, int depth) {
    if (depth > kMaxDepth) return fail("sequences nested more than 32 deep");
    while (pos < end) {
      if (end - pos < 8) return fail("truncated: " + std::to_string(end - pos) + " stray bytes at the end of a data set");
      const bool big = big_endian;
      const uint16_t group = u16(pos, big);
      const uint16_t element = u16(pos + 2, big);
      if (group == 0xFFFE) {
        const uint32_t length = u32(pos + 4, big);
        if (element == 0xE00D && item) {  // item delimitation
          pos += 8;
          return true;
        }
        return fail("unexpected item tag " + tag_text(group, element) + " with length " +
                    std::to_string(length) + " in a data set");
      }
      char vr[2] = {0, 0};
      uint32_t length = 0;
      size_t header = 8;
      if (explicit_vr) {
        vr[0] = char(bytes[pos + 4]);
        vr[1] = char(bytes[pos + 5]);
        if (!is_known_vr(vr)) {
          return fail("element " + tag_text(group, element) + " has no valid value representation");
        }
        if (vr_error.empty()) vr_error = dictionary_vr_mismatch(group, element, vr);
        if (is_long_vr(vr)) {
          if (end - pos < 12) return truncated(group, element, 12, end - pos);
          length = u32(pos + 8, big);
          header = 12;
        } else {
          length = u16(pos + 6, big);
        }
      } else {
        length = u32(pos + 4, big);
      }
      pos += header;
      const bool is_pixel_data = group == 0x7FE0 && element == 0x0010 && depth == 0;
      if (length == kUndefined) {
        const bool sequence = !explicit_vr || (vr[0] == 'S' && vr[1] == 'Q') ||
                              (vr[0] == 'U' && vr[1] == 'N') || is_pixel_data;
        if (!sequence) {
          return fail("element " + tag_text(group, element) + " has an undefined length");
        }
        if (is_pixel_data) {
          pixel_data = true;
          pixel_encapsulated = true;
        }
        if (!items(pos, end, true, is_pixel_data, depth)) return false;
        continue;
      }
      if (length > end - pos) return truncated(group, element, length, end - pos);
      if (explicit_vr && vr[0] == 'S' && vr[1] == 'Q') {
        size_t inner = pos;
        if (!items(inner, pos + length, false, false, depth)) return false;
      } else if (depth == 0) {
        record(group, element, vr, pos, length);
      }
      pos += length;
    }
    if (item) return fail("truncated: an item of undefined length has no end");
    return true;
  }

  // The items of a sequence (or the fragments of encapsulated pixel data) from pos; with
  // `undefined`, up to a sequence delimitation item, else up to `end`.
  bool items(size_t& pos, size_t end, bool undefined, bool fragments, int depth) {
    if (depth + 1 > kMaxDepth) return fail("sequences nested more than 32 deep");
    while (pos < end || undefined) {
      if (end - pos < 8) {
        return fail(undefined ? "truncated: a sequence of undefined length has no end"
                              : "truncated: a sequence item header is cut short");
      }
      const bool big = big_endian;
      const uint16_t group = u16(pos, big);
      const uint16_t element = u16(pos + 2, big);
      const uint32_t length = u32(pos + 4, big);
      pos += 8;
      if (group != 0xFFFE) {
        return fail("a sequence holds element " + tag_text(group, element) + " instead of an item");
      }
      if (element == 0xE0DD) {  // sequence delimitation
        if (!undefined) return fail("a sequence of defined length holds a sequence delimiter");
        return true;
      }
      if (element != 0xE000) return fail("unexpected item tag " + tag_text(group, element));
      if (length == kUndefined) {
        if (fragments) return fail("a pixel data fragment has an undefined length");
        if (!data_set(pos, end, true, depth + 1)) return false;
        continue;
      }
      if (length > end - pos) return truncated(group, element, length, end - pos);
      if (fragments) {
        pixel_length += length;
      } else {
        size_t inner = pos;
        if (!data_set(inner, pos + length, false, depth + 1)) return false;
      }
      pos += length;
    }
    return true;
  }

  // The image pixel module of the top-level data set. GDCM asserts (aborts) on a pixel format it
  // cannot name (fuzz_dicom: PixelFormat::GetScalarType), so these must be plain US values.
  void record(uint16_t group, uint16_t element, const char* vr, size_t at, uint32_t length) {
    if (group == 0x0028 && (element == 0x0002 || element == 0x0010 || element == 0x0011 ||
                            element == 0x0100 || element == 0x0101 || element == 0x0102 ||
                            element == 0x0103)) {
      if (length != 2 || (explicit_vr && !(vr[0] == 'U' && vr[1] == 'S'))) {
        if (format_error.empty()) {
          format_error = "the image pixel element " + tag_text(group, element) +
                         " is not a 2-byte US value";
        }
        return;
      }
      const int64_t value = u16(at, big_endian);
      if (element == 0x0002) samples = value;
      if (element == 0x0010) rows = value;
      if (element == 0x0011) columns = value;
      if (element == 0x0100) bits_allocated = value;
      if (element == 0x0101) bits_stored = value;
      if (element == 0x0102) high_bit = value;
      if (element == 0x0103) pixel_representation = value;
    } else if (group == 0x0028 && element == 0x0008 && length > 0 && length < 16) {
      const std::string text(reinterpret_cast<const char*>(bytes + at), length);
      frames = std::max<int64_t>(1, std::atoll(text.c_str()));
    } else if (group == 0x7FE0 && element == 0x0010) {
      pixel_data = true;
      pixel_length = length;
    }
  }
};

DicomFileCheck finish(Walker& w) {
  if (!w.pixel_data) return {DicomFileStatus::not_image, "no pixel data"};
  if (!w.format_error.empty()) return {DicomFileStatus::broken, w.format_error};
  // Only a file GDCM will read as an image matters; other DICOM files are skipped before GDCM.
  if (!w.vr_error.empty()) return {DicomFileStatus::broken, w.vr_error};
  const auto bad = [](const std::string& what) {
    return DicomFileCheck{DicomFileStatus::broken, "the pixel format is not valid: " + what};
  };
  if (w.rows < 1 || w.columns < 1) return bad("no Rows and Columns");
  const int64_t ba = w.bits_allocated;
  if (!(ba == 1 || ba == 8 || ba == 16 || ba == 32 || ba == 64)) {
    return bad("BitsAllocated " + std::to_string(ba) + " (1, 8, 16, 32 or 64)");
  }
  if (w.bits_stored < 1 || w.bits_stored > ba) {
    return bad("BitsStored " + std::to_string(w.bits_stored) + " with BitsAllocated " +
               std::to_string(ba));
  }
  if (w.high_bit >= ba || (w.high_bit >= 0 && w.high_bit + 1 < w.bits_stored)) {
    return bad("HighBit " + std::to_string(w.high_bit) + " with BitsStored " +
               std::to_string(w.bits_stored));
  }
  if (w.pixel_representation != 0 && w.pixel_representation != 1) {
    return bad("PixelRepresentation " + std::to_string(w.pixel_representation));
  }
  if (w.samples != 1 && w.samples != 3) return bad("SamplesPerPixel " + std::to_string(w.samples));
  {
    const uint64_t bits = uint64_t(w.rows) * uint64_t(w.columns) * uint64_t(std::max<int64_t>(1, w.samples)) *
                          uint64_t(w.frames) * uint64_t(w.bits_allocated);
    const uint64_t needed = (bits + 7) / 8;
    if (!w.pixel_encapsulated && w.pixel_length < needed) {
      return {DicomFileStatus::broken,
              "truncated: the pixel data holds " + std::to_string(w.pixel_length) +
                  " bytes where " + std::to_string(w.rows) + " rows x " +
                  std::to_string(w.columns) + " columns need " + std::to_string(needed)};
    }
  }
  return {DicomFileStatus::image, {}};
}

}  // namespace

DicomFileCheck check_dicom_file(const std::filesystem::path& file) {
  const MappedFile mapped(file);
  if (!mapped.opened()) return {DicomFileStatus::unreadable, std::strerror(mapped.error())};
  const unsigned char* bytes = mapped.data();
  const size_t size = mapped.size();
  if (size == 0) return {DicomFileStatus::not_dicom, "empty file"};

  const bool part10 = size >= 132 && std::memcmp(bytes + 128, "DICM", 4) == 0;
  if (!part10) {
    // A bare data set (no preamble), as old ACR-NEMA style files are: implicit VR little endian,
    // starting with a group 0008 element. Anything else is not DICOM.
    if (size < 8 || bytes[0] != 0x08 || bytes[1] != 0x00) {
      return {DicomFileStatus::not_dicom, "no DICOM preamble"};
    }
    Walker w{bytes, size};
    w.explicit_vr = (bytes[4] >= 'A' && bytes[4] <= 'Z' && bytes[5] >= 'A' && bytes[5] <= 'Z');
    size_t pos = 0;
    if (!w.data_set(pos, size, false, 0)) return {DicomFileStatus::not_dicom, w.error};
    return finish(w);
  }

  // File meta information: group 0002, explicit VR little endian.
  Walker meta{bytes, size};
  size_t pos = 132;
  std::string transfer_syntax;
  std::string meta_vr_error;
  while (size - pos >= 8 && meta.u16(pos, false) == 0x0002) {
    const uint16_t element = meta.u16(pos + 2, false);
    size_t end = pos;
    {
      const char* vr = reinterpret_cast<const char*>(bytes + pos + 4);
      if (!is_known_vr(vr)) {
        return {DicomFileStatus::broken, "the file meta element " + tag_text(2, element) +
                                             " has no valid value representation"};
      }
      if (meta_vr_error.empty()) meta_vr_error = dictionary_vr_mismatch(2, element, vr);
      size_t header = 8;
      uint32_t length = meta.u16(pos + 6, false);
      if (is_long_vr(vr)) {
        if (size - pos < 12) return {DicomFileStatus::broken, "truncated in the file meta information"};
        length = meta.u32(pos + 8, false);
        header = 12;
      }
      if (length == kUndefined || length > size - pos - header) {
        return {DicomFileStatus::broken, "truncated: the file meta element " + tag_text(2, element) +
                                             " runs past the end of the file"};
      }
      if (element == 0x0010) {  // UI values are padded with a NUL, some writers use a space
        const std::string_view value(reinterpret_cast<const char*>(bytes + pos + header), length);
        transfer_syntax = std::string(trim_end(value, std::string_view("\0 ", 2)));
      }
      end = pos + header + length;
    }
    pos = end;
  }
  // The transfer syntax is mandatory. Without it GDCM guesses how to read the rest, differently
  // from this walk, and may allocate what it guessed (fuzz_dicom: 4 GB for a 9.6 kB file whose
  // meta group began with a group-0000 element).
  if (transfer_syntax.empty()) {
    return {DicomFileStatus::broken,
            "the file meta information is missing or names no transfer syntax (0002,0010)"};
  }
  if (pos >= size) return {DicomFileStatus::broken, "truncated: the file ends after its meta information"};
  if (size - pos < 8) return {DicomFileStatus::broken, "truncated: the data set is cut short"};

  Walker w{bytes, size};
  if (transfer_syntax == "1.2.840.10008.1.2") {
    w.explicit_vr = false;
  } else if (transfer_syntax == "1.2.840.10008.1.2.2") {
    w.big_endian = true;
  } else if (transfer_syntax == "1.2.840.10008.1.2.1.99") {
    return {DicomFileStatus::broken,
            "uses the deflated transfer syntax, which segmesh does not read; convert the series "
            "with an uncompressed transfer syntax"};
  }
  if (!w.data_set(pos, size, false, 0)) return {DicomFileStatus::broken, w.error};
  if (!meta_vr_error.empty()) w.vr_error = meta_vr_error;
  return finish(w);
}

}  // namespace segmesh::volume_io
