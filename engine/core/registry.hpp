// Drape's entity-component store: generational entity handles and sparse-set pools.
//
// - An `Entity` is an index plus a generation. Destroying an entity bumps the generation of
//   its slot, so an old handle is detected as stale (`valid()` is false, `try_get` returns
//   null) instead of silently addressing whatever reuses the slot.
// - Each component type lives in its own sparse set: a sparse index array (entity index ->
//   dense position) and dense arrays of entities and components, packed with swap-and-pop.
// - A view over several types iterates the smallest pool and checks the others; a missing
//   or empty pool makes the view empty in O(1).
//
// Iteration contract (tested in tests/engine/registry_test.cpp): a view walks its leading
// pool from the back. While iterating, the callback may remove components from, or destroy,
// the entity it is visiting, and may create entities or add components to other entities;
// every entity present before the loop and not removed is visited exactly once. Removing
// components of *other* entities during iteration is not supported (an entity may then be
// skipped or visited twice); collect them and remove after the loop.
#pragma once

#include <atomic>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace drape {

/// A handle to an entity: slot index plus generation. Default-constructed = null.
struct Entity {
    std::uint32_t index = std::numeric_limits<std::uint32_t>::max();
    std::uint32_t generation = 0;

    [[nodiscard]] constexpr bool is_null() const noexcept {
        return index == std::numeric_limits<std::uint32_t>::max();
    }
    friend constexpr bool operator==(Entity, Entity) noexcept = default;
};

inline constexpr Entity null_entity{};

/// Dense id of a component type, assigned on first use (process-wide, thread-safe).
using ComponentId = std::uint32_t;

namespace detail {
inline ComponentId next_component_id() noexcept {
    static std::atomic<ComponentId> counter{0};
    return counter++;
}
}  // namespace detail

template <class T>
[[nodiscard]] ComponentId component_id() noexcept {
    static const ComponentId id = detail::next_component_id();
    return id;
}

/// Type-erased part of a pool, so the registry can remove a destroyed entity from all pools.
class PoolBase {
public:
    virtual ~PoolBase() = default;
    [[nodiscard]] virtual bool contains(Entity e) const noexcept = 0;
    virtual bool remove(Entity e) = 0;
    [[nodiscard]] virtual std::size_t size() const noexcept = 0;
};

/// Sparse set of components of one type.
template <class T>
class Pool final : public PoolBase {
public:
    static constexpr std::uint32_t npos = std::numeric_limits<std::uint32_t>::max();

    [[nodiscard]] bool contains(Entity e) const noexcept override {
        return e.index < m_sparse.size() && m_sparse[e.index] != npos &&
               m_entities[m_sparse[e.index]] == e;
    }

    template <class... Args>
    T& emplace(Entity e, Args&&... args) {
        assert(!contains(e) && "Pool::emplace: entity already has this component");
        if (e.index >= m_sparse.size()) m_sparse.resize(e.index + 1, npos);
        m_sparse[e.index] = static_cast<std::uint32_t>(m_entities.size());
        m_entities.push_back(e);
        if constexpr (std::is_aggregate_v<T>)
            m_components.push_back(T{std::forward<Args>(args)...});
        else
            m_components.emplace_back(std::forward<Args>(args)...);
        return m_components.back();
    }

    bool remove(Entity e) override {
        if (!contains(e)) return false;
        const std::uint32_t pos = m_sparse[e.index];
        const std::uint32_t last = static_cast<std::uint32_t>(m_entities.size() - 1);
        if (pos != last) {
            m_entities[pos] = m_entities[last];
            m_components[pos] = std::move(m_components[last]);
            m_sparse[m_entities[pos].index] = pos;
        }
        m_entities.pop_back();
        m_components.pop_back();
        m_sparse[e.index] = npos;
        return true;
    }

    [[nodiscard]] T* find(Entity e) noexcept { return contains(e) ? &m_components[m_sparse[e.index]] : nullptr; }
    [[nodiscard]] const T* find(Entity e) const noexcept {
        return contains(e) ? &m_components[m_sparse[e.index]] : nullptr;
    }
    [[nodiscard]] std::size_t size() const noexcept override { return m_entities.size(); }
    [[nodiscard]] const std::vector<Entity>& entities() const noexcept { return m_entities; }
    [[nodiscard]] T& at_dense(std::size_t i) noexcept { return m_components[i]; }

private:
    std::vector<std::uint32_t> m_sparse;
    std::vector<Entity> m_entities;
    std::vector<T> m_components;
};

class Registry;

/// Entities that have every component in `Ts...`. Cheap to create; see the iteration
/// contract at the top of this file.
template <class... Ts>
class View {
public:
    explicit View(std::tuple<Pool<Ts>*...> pools) : m_pools(pools) {}

    /// Calls `f(Entity, Ts&...)` for each matching entity.
    template <class F>
    void each(F&& f) {
        PoolBase* lead = leading();
        if (lead == nullptr) return;
        const std::vector<Entity>& entities = lead_entities(lead);
        for (std::size_t i = entities.size(); i-- > 0;) {
            if (i >= entities.size()) {  // the callback removed several; restart from the end
                if (entities.empty()) return;
                i = entities.size() - 1;
            }
            const Entity e = entities[i];
            if ((std::get<Pool<Ts>*>(m_pools)->contains(e) && ...))
                f(e, *std::get<Pool<Ts>*>(m_pools)->find(e)...);
        }
    }

    /// Size of the smallest pool: an upper bound on the number of matches.
    [[nodiscard]] std::size_t size_hint() const noexcept {
        const PoolBase* lead = leading();
        return lead ? lead->size() : 0;
    }

    /// Matching entities, in iteration order, collected into a vector.
    [[nodiscard]] std::vector<Entity> entities() {
        std::vector<Entity> out;
        each([&](Entity e, Ts&...) { out.push_back(e); });
        return out;
    }

private:
    [[nodiscard]] PoolBase* leading() const noexcept {
        PoolBase* best = nullptr;
        bool missing = false;
        auto consider = [&](PoolBase* p) {
            if (p == nullptr) { missing = true; return; }
            if (best == nullptr || p->size() < best->size()) best = p;
        };
        (consider(std::get<Pool<Ts>*>(m_pools)), ...);
        return missing ? nullptr : best;
    }
    template <std::size_t I = 0>
    const std::vector<Entity>& lead_entities(PoolBase* lead) const {
        using P = std::tuple_element_t<I, std::tuple<Pool<Ts>*...>>;
        if constexpr (I + 1 < sizeof...(Ts)) {
            if (static_cast<PoolBase*>(std::get<I>(m_pools)) != lead) return lead_entities<I + 1>(lead);
        }
        return static_cast<P>(lead)->entities();
    }

    std::tuple<Pool<Ts>*...> m_pools;
};

/// Owns entities and their components.
class Registry {
public:
    /// Creates an entity with no components.
    [[nodiscard]] Entity create() {
        if (!m_free.empty()) {
            const std::uint32_t index = m_free.back();
            m_free.pop_back();
            return Entity{index, m_generations[index]};
        }
        m_generations.push_back(0);
        return Entity{static_cast<std::uint32_t>(m_generations.size() - 1), 0};
    }

    /// Removes every component of `e` and retires the handle. Stale handles are ignored.
    void destroy(Entity e) {
        if (!valid(e)) return;
        for (auto& pool : m_pools)
            if (pool) pool->remove(e);
        ++m_generations[e.index];
        m_free.push_back(e.index);
    }

    /// True while `e` has not been destroyed.
    [[nodiscard]] bool valid(Entity e) const noexcept {
        return !e.is_null() && e.index < m_generations.size() && m_generations[e.index] == e.generation;
    }

    /// Number of live entities.
    [[nodiscard]] std::size_t alive() const noexcept { return m_generations.size() - m_free.size(); }

    /// Adds a component to a live entity that does not have one of this type yet.
    template <class T, class... Args>
    T& emplace(Entity e, Args&&... args) {
        assert(valid(e) && "Registry::emplace: stale or null entity");
        return pool<T>().emplace(e, std::forward<Args>(args)...);
    }

    /// Adds or replaces.
    template <class T>
    T& emplace_or_replace(Entity e, T value) {
        if (T* existing = try_get<T>(e)) { *existing = std::move(value); return *existing; }
        return emplace<T>(e, std::move(value));
    }

    /// The component of `e`; `e` must have it (asserted).
    template <class T>
    [[nodiscard]] T& get(Entity e) {
        T* c = try_get<T>(e);
        assert(c != nullptr && "Registry::get: entity has no such component (or is stale)");
        return *c;
    }

    /// The component of `e`, or null when `e` is stale or has none.
    template <class T>
    [[nodiscard]] T* try_get(Entity e) noexcept {
        Pool<T>* p = find_pool<T>();
        return p && valid(e) ? p->find(e) : nullptr;
    }
    template <class T>
    [[nodiscard]] const T* try_get(Entity e) const noexcept {
        const Pool<T>* p = find_pool<T>();
        return p && valid(e) ? p->find(e) : nullptr;
    }

    template <class T>
    [[nodiscard]] bool has(Entity e) const noexcept { return try_get<T>(e) != nullptr; }

    /// Removes the component if present; returns whether it was.
    template <class T>
    bool remove(Entity e) {
        Pool<T>* p = find_pool<T>();
        return p && valid(e) && p->remove(e);
    }

    /// How many entities have a component of type T.
    template <class T>
    [[nodiscard]] std::size_t count() const noexcept {
        const Pool<T>* p = find_pool<T>();
        return p ? p->size() : 0;
    }

    /// How many entities have the component with this id (0 for unknown ids).
    [[nodiscard]] std::size_t count(ComponentId id) const noexcept {
        return id < m_pools.size() && m_pools[id] ? m_pools[id]->size() : 0;
    }

    /// Entities with every component in Ts, led by the smallest pool.
    template <class... Ts>
    [[nodiscard]] View<Ts...> view() {
        return View<Ts...>(std::tuple<Pool<Ts>*...>(find_pool<Ts>()...));
    }

    /// Calls `f(Entity, const Ts&...)` for each entity with every component in Ts, read-only
    /// (the view's iteration contract, without changes to the components).
    template <class... Ts, class F>
    void each(F&& f) const {
        View<Ts...>(std::tuple<Pool<Ts>*...>(find_pool<Ts>()...)).each([&](Entity e, Ts&... c) { f(e, std::as_const(c)...); });
    }

private:
    template <class T>
    Pool<T>& pool() {
        const ComponentId id = component_id<T>();
        if (id >= m_pools.size()) m_pools.resize(id + 1);
        if (!m_pools[id]) m_pools[id] = std::make_unique<Pool<T>>();
        return static_cast<Pool<T>&>(*m_pools[id]);
    }
    template <class T>
    Pool<T>* find_pool() const noexcept {
        const ComponentId id = component_id<T>();
        return id < m_pools.size() ? static_cast<Pool<T>*>(m_pools[id].get()) : nullptr;
    }

    std::vector<std::uint32_t> m_generations;
    std::vector<std::uint32_t> m_free;
    std::vector<std::unique_ptr<PoolBase>> m_pools;
};

}  // namespace drape
