#include "tools/vitrine/serve/events.hpp"

namespace vitrine::serve {

void EventHub::publish(const std::string& type, nlohmann::json data) {
    {
        std::lock_guard lock(mMutex);
        mEvents.push_back({mNext++, type, std::move(data)});
        while (mEvents.size() > mKeep)
            mEvents.pop_front();
    }
    mChanged.notify_all();
}

std::vector<Event> EventHub::waitAfter(uint64_t after, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mMutex);
    mChanged.wait_for(lock, timeout, [&] { return mClosed || mNext - 1 > after; });
    std::vector<Event> out;
    if (mClosed) return out;
    for (const Event& e : mEvents)
        if (e.id > after) out.push_back(e);
    return out;
}

uint64_t EventHub::lastId() const {
    std::lock_guard lock(mMutex);
    return mNext - 1;
}

void EventHub::close() {
    {
        std::lock_guard lock(mMutex);
        mClosed = true;
    }
    mChanged.notify_all();
}

bool EventHub::closed() const {
    std::lock_guard lock(mMutex);
    return mClosed;
}

std::string EventHub::format(const Event& event) {
    return "id: " + std::to_string(event.id) + "\nevent: " + event.type + "\ndata: " + event.data.dump() + "\n\n";
}

} // namespace vitrine::serve
