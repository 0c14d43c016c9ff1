// bireg: deterministic parallel sums over observations. The observations
// are cut into chunks of kChunkSize, a number independent of the thread
// count; each chunk's partial sum is computed by whichever thread claims
// it, and the partial sums are combined in chunk order by the caller. The
// arithmetic is therefore the same for any thread count, including one:
// a serial fit of more than one chunk adds the same partial sums in the
// same order, so results are bit-identical whatever `threads` is.
//
// ChunkPool starts threads - 1 workers once (per fit) and reuses them for
// every sum; the calling thread works too. A run publishes a function
// pointer and a context (no std::function, no allocation per run).
//
// Workers are bounded: never more than the tasks a pool is told it will
// run (the chunks of a fit, the candidates of a selection) minus one, and
// never more than kMaxWorkers, whatever `threads` asks for. A worker the
// system refuses to start (std::thread throws std::system_error under
// RLIMIT_NPROC, or std::bad_alloc when memory is short) is not an error:
// the pool keeps the workers it has (possibly none) and the calling thread
// does the rest. Since the arithmetic does not depend on which thread
// computes a chunk, the results are the same bit for bit.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <limits>
#include <mutex>
#include <new>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace bireg {

// Observations per chunk of a parallel sum.
inline constexpr std::size_t kChunkSize = 4096;

// Below this many observations a fit stays serial whatever `threads` is:
// waking the workers costs more than the chunks they would share.
inline constexpr std::size_t kParallelMinimum = 2 * kChunkSize;

// Chunks (or pieces) of `size` that cover n items, the last one short.
inline std::size_t chunk_count(std::size_t n, std::size_t size = kChunkSize) {
  return (n + size - 1) / size;
}

// At most this many workers per pool (kMaxThreads threads with the calling
// one): far more than a machine's cores, far fewer than would exhaust its
// memory or its process limit (each worker reserves a stack).
inline constexpr std::size_t kMaxWorkers = 255;
inline constexpr int kMaxThreads = static_cast<int>(kMaxWorkers) + 1;

namespace parallel_detail {
// Test seam: when set, called before worker k (0-based) of a pool starts;
// returning true makes that start fail as a refused std::thread does (a
// std::system_error), so tests can exercise the fallback where the process
// limit cannot be lowered (as root). Not for production use.
inline bool (*refuse_worker_for_testing)(std::size_t worker) = nullptr;
}  // namespace parallel_detail

class ChunkPool {
 public:
  // Up to threads - 1 workers, fewer when the pool will never have that
  // many tasks at once (`tasks`: the largest `chunks` of any run) or when
  // that exceeds kMaxWorkers; fewer still if the system refuses to start
  // them (then threads() says how many there are).
  explicit ChunkPool(int threads, std::size_t tasks = std::numeric_limits<std::size_t>::max()) {
    const std::size_t requested = threads > 1 ? static_cast<std::size_t>(threads - 1) : 0;
    const std::size_t useful = tasks > 0 ? tasks - 1 : 0;  // the caller takes one task
    const std::size_t worker_count = std::min({requested, useful, kMaxWorkers});
    workers_.reserve(worker_count);
    for (std::size_t k = 0; k < worker_count; ++k) {
      try {
        if (parallel_detail::refuse_worker_for_testing &&
            parallel_detail::refuse_worker_for_testing(k)) {
          throw std::system_error(std::make_error_code(std::errc::resource_unavailable_try_again));
        }
        workers_.emplace_back([this] { serve(); });
      } catch (const std::system_error&) {
        break;  // the workers started so far serve; the caller does the rest
      } catch (const std::bad_alloc&) {
        break;
      }
    }
  }
  ChunkPool(const ChunkPool&) = delete;
  ChunkPool& operator=(const ChunkPool&) = delete;
  ~ChunkPool() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& worker : workers_)
      worker.join();
  }

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls body(chunk) once for every chunk in [0, chunks), on any thread,
  // and returns when all calls have returned. body must not throw.
  template <class Body>
  void run(std::size_t chunks, const Body& body) {
    if (workers_.empty() || chunks < 2) {
      for (std::size_t chunk = 0; chunk < chunks; ++chunk)
        body(chunk);
      return;
    }
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      task_ = [](const void* context, std::size_t chunk) {
        (*static_cast<const Body*>(context))(chunk);
      };
      context_ = &body;
      chunks_ = chunks;
      next_.store(0);
      busy_ = workers_.size();
      ++generation_;
    }
    wake_.notify_all();
    drain();
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return busy_ == 0; });
  }

 private:
  void drain() {
    for (std::size_t chunk = next_.fetch_add(1); chunk < chunks_; chunk = next_.fetch_add(1)) {
      task_(context_, chunk);
    }
  }

  void serve() {
    std::size_t seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
        if (stopping_) return;
        seen = generation_;
      }
      drain();
      const std::lock_guard<std::mutex> lock(mutex_);
      if (--busy_ == 0) done_.notify_one();
    }
  }

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::size_t generation_ = 0;
  bool stopping_ = false;
  void (*task_)(const void*, std::size_t) = nullptr;
  const void* context_ = nullptr;
  std::size_t chunks_ = 0;
  std::atomic<std::size_t> next_{0};
  std::size_t busy_ = 0;
};

// body(piece) for every piece in [0, pieces): on the pool's threads when
// there is one, in order on the caller's otherwise.
template <class Body>
void run_pieces(ChunkPool* pool, std::size_t pieces, const Body& body) {
  if (pool) {
    pool->run(pieces, body);
  } else {
    for (std::size_t piece = 0; piece < pieces; ++piece)
      body(piece);
  }
}

// body(begin, end) over [0, n) in ranges of `size` (the last one short),
// on the pool's threads when there is one.
template <class Body>
void run_ranges(ChunkPool* pool, std::size_t n, std::size_t size, const Body& body) {
  run_pieces(pool, chunk_count(n, size),
             [&](std::size_t piece) { body(piece * size, std::min(n, (piece + 1) * size)); });
}

// A once-per-fit pass over observations [0, n) (the observation check, the
// chart, the Gauss-Newton moments, the diagnostics) by chunks:
// body(begin, end) returns a chunk's Partial, and combine(total, next)
// folds the partials into the first in chunk order, so the result is the
// same arithmetic with or without a pool, for any thread count. One chunk
// calls body(0, n) and allocates nothing; more allocate their partials
// once (not for the iteration's loop: the force keeps its own workspace).
template <class Partial, class Body, class Combine>
Partial reduce_chunks(std::size_t n, ChunkPool* pool, const Body& body, const Combine& combine) {
  const std::size_t chunks = chunk_count(n);
  if (chunks <= 1) return body(std::size_t(0), n);
  std::vector<Partial> partials(chunks);
  const auto run_chunk = [&](std::size_t chunk) {
    partials[chunk] = body(chunk * kChunkSize, std::min(n, (chunk + 1) * kChunkSize));
  };
  run_pieces(pool, chunks, run_chunk);
  Partial total = std::move(partials[0]);
  for (std::size_t chunk = 1; chunk < chunks; ++chunk)
    combine(total, partials[chunk]);
  return total;
}

}  // namespace bireg
