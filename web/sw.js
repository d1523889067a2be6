// The page's service worker: lets a page opened once from a static host reopen offline. On install
// it stores every file a `web/build.sh --dist` folder lists in its build.json (web/ itself has none:
// there it keeps only what it sees fetched). Network first, so a rebuilt page is never served stale
// while online; the cache answers when the network does not.
const CACHE = "artmesh-page";

self.addEventListener("install", (event) => {
  event.waitUntil((async () => {
    const listing = await fetch("build.json", { cache: "no-store" }).catch(() => null);
    if (listing?.ok) {
      const { files } = await listing.json();
      await (await caches.open(CACHE)).addAll(["./", ...files]);
    }
    await self.skipWaiting();
  })());
});
self.addEventListener("activate", (event) => event.waitUntil(self.clients.claim()));

self.addEventListener("fetch", (event) => {
  const request = event.request;
  if (request.method !== "GET" || new URL(request.url).origin !== self.location.origin) return;
  event.respondWith(
    fetch(request)
      .then((response) => {
        // The copy is stored after the page has its answer.
        if (response.ok) {
          const copy = response.clone();
          event.waitUntil(caches.open(CACHE).then((cache) => cache.put(request, copy)));
        }
        return response;
      })
      // A reopened page's address may carry a query (?max=…); the files never do.
      .catch(async () => (await caches.match(request, { ignoreSearch: request.mode === "navigate" })) ??
        Response.error()),
  );
});
