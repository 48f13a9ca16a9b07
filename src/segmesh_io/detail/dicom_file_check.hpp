// A structural check of one DICOM file before GDCM (through ITK) reads it. Internal to segmesh_io.
//
// GDCM, as Debian builds it, aborts the process on some broken files (an assert in its file meta
// reader when a file is cut short) and reads a slice whose pixel data is cut short "successfully",
// filling the missing voxels, with only a warning on stderr. So every file is walked here first:
// the preamble and "DICM" magic, the file meta group, then every data element of the data set in
// the transfer syntax it names (explicit or implicit VR, either byte order), into sequences and
// items (defined or undefined length, nested at most 32 deep) and encapsulated pixel data
// fragments. Every length must fit in the file; only the value representations of PS3.5 are
// accepted (GDCM reads an unknown one with a 32-bit length and allocates it), and in an image a
// public element must carry the VR GDCM's dictionary gives it, or UN (GDCM asserts when it reads
// the element as a typed attribute); the file meta group must name its transfer syntax; the image
// pixel elements must be plain US values describing a pixel format GDCM can name (it asserts
// otherwise); and uncompressed pixel data must hold at least rows x columns x samples x frames x
// bits allocated. Each of these rules closes a crash, hang or memory blow-up found by
// fuzz/fuzz_dicom.cpp (docs/ROBUSTNESS.md). Nothing is allocated; the file is mapped read-only.
// Cost: one pass over the element headers (values are skipped, not read) and a dictionary look-up
// per element.
#pragma once

#include <filesystem>
#include <string>

namespace segmesh::volume_io {

enum class DicomFileStatus {
  image,      // a well-formed DICOM file with pixel data
  not_image,  // well-formed DICOM without pixel data (DICOMDIR, structured report, ...)
  not_dicom,  // no DICOM structure at all (a text file, a thumbnail, an empty file)
  broken,     // DICOM (the "DICM" magic or a DICOM data set start) that is truncated or corrupt
  unreadable, // the file cannot be opened or read (permissions, I/O error): what it is is unknown
};

struct DicomFileCheck {
  DicomFileStatus status = DicomFileStatus::not_dicom;
  std::string reason;  // why, for not_dicom and broken: "truncated: element (7fe0,0010) ..."
};

DicomFileCheck check_dicom_file(const std::filesystem::path& file);

}  // namespace segmesh::volume_io
