import { defineConfig } from 'vite';

// `npm run dev` serves the page with hot reload and forwards the API to a running
// `nurbsx serve` (default 127.0.0.1:8080, or NURBSX_URL).
const api = process.env.NURBSX_URL ?? 'http://127.0.0.1:8080';

export default defineConfig({
  build: { outDir: 'dist', emptyOutDir: true, chunkSizeWarningLimit: 1000 },
  server: {
    proxy: Object.fromEntries(
      ['/v1', '/limits', '/api', '/openapi.json', '/healthz'].map((p) => [p, api]),
    ),
  },
});
