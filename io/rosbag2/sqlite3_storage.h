#pragma once
// rosbag2's sqlite3 storage (.db3). The schema, as the recorder writes it (read from the bags in
// ../shared/data/rosbag2; rosbag2_storage_sqlite3, schema versions 1-4 agree on these columns):
//   topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, serialization_format TEXT,
//          offered_qos_profiles TEXT [v2+], type_description_hash TEXT [v4+])
//   messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, data BLOB)
//   + index timestamp_idx on messages(timestamp); v3+ add tables schema and metadata, v4
//   message_definitions. Only the columns above the line are read, so every version opens.

#include <memory>
#include <string>

#include "io/rosbag2/storage.h"

namespace fitcal::io::rosbag2 {

// Opens one .db3 file read-only. Throws InputError when it is missing, not an SQLite database,
// or lacks the rosbag2 tables.
std::unique_ptr<StorageReader> OpenSqlite3Storage(const std::string& path);

}  // namespace fitcal::io::rosbag2
