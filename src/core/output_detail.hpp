#pragma once
// A seam for tests of output.cpp: what is synced to disk, and when.
namespace rwcalc::detail {

enum class SyncedKind { File, Directory };
/// Called right after each successful fsync of an output (the finished temporary file, then the
/// directory after the rename) with the descriptor synced. Null: nobody is told.
using SyncObserver = void (*)(SyncedKind kind, int fd);
void set_sync_observer(SyncObserver observer);

}  // namespace rwcalc::detail
