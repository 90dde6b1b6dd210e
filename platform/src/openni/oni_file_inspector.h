// Reads the record structure of an OpenNI file (.oni) without decoding any frame, so a file that
// OpenNI2's file driver would refuse silently (truncated: it needs the seek table and the End
// record at the tail) or stall on is refused up front with the offset and the rule broken. It also
// recovers what OpenNI2's playback API does not expose for OpenNI 1.x recordings: the per-node
// "Mirror" and "AlternativeViewPoint" (depth registered to colour) flags.
//
// Layout (OpenNI 1.x/2.x "NI10" files): a 24-byte header {char magic[4] = "NI10"; u8 major, minor;
// u16 maintenance; u32 build; u64 max_timestamp_us; u32 max_node_id}, then records, each a 28-byte
// header {char magic[4] = "NIR\0"; u32 type; u32 node_id; u32 fields_size (header included);
// u32 payload_size; u64 undo_position} followed by fields and payload. The last record has type
// End (11) and ends exactly at the end of the file.
#pragma once
#include <cstdint>
#include <map>
#include <string>

#include "mrgi/expected.h"

namespace mrgi::oni {

struct NodeSummary {
  std::string name;            // "Depth1", "Image1", ... (from the NodeAdded record)
  int64_t data_records = 0;    // frames stored for this node
  std::map<std::string, uint64_t> int_properties;  // IntProperty records, last value wins
};

struct FileSummary {
  int version_major = 0, version_minor = 0;
  uint64_t max_timestamp_us = 0;
  int64_t record_count = 0;
  std::map<uint32_t, NodeSummary> nodes;  // by node id
  // Node whose name starts with "Depth" / "Image"; 0 when absent.
  uint32_t depth_node = 0, image_node = 0;
  // Reads an int property of a node; `fallback` when the node or the property is absent.
  uint64_t int_property(uint32_t node, const std::string& name, uint64_t fallback) const;
};

// Walks every record of PATH. Errors (BadInput) name the file, the byte offset and the rule:
// wrong magic, a record running past the end (truncated), no End record, a bad record magic.
Expected<FileSummary> inspect_oni_file(const std::string& path);

}  // namespace mrgi::oni
