#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

// Progress of `vitrine serve`'s jobs for GET /api/events (server-sent events): a job is queued, compiles, renders
// frame k of n, is done or failed. Publishers are the HTTP threads and the GPU thread; every events connection waits
// here for what follows the last event it sent.
namespace vitrine::serve {

struct Event {
    uint64_t id = 0;  // increasing from 1; the SSE `id:` field, so a reconnecting client resumes (Last-Event-ID)
    std::string type; // the SSE `event:` field: "job" or "hello"
    nlohmann::json data;
};

class EventHub {
public:
    explicit EventHub(size_t keep = 512) : mKeep(keep) {}

    void publish(const std::string& type, nlohmann::json data);

    // The events after `after` that are still kept, waiting up to `timeout` for one when there are none. Empty on
    // time-out or once closed.
    std::vector<Event> waitAfter(uint64_t after, std::chrono::milliseconds timeout);
    uint64_t lastId() const;

    // Wakes every waiting connection for good (the server is stopping).
    void close();
    bool closed() const;

    // SSE wire format of one event.
    static std::string format(const Event& event);

private:
    mutable std::mutex mMutex;
    std::condition_variable mChanged;
    std::deque<Event> mEvents;
    size_t mKeep;
    uint64_t mNext = 1;
    bool mClosed = false;
};

} // namespace vitrine::serve
