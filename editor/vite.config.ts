import { defineConfig } from 'vite';
import react from '@vitejs/plugin-react';

// `npm run dev` proxies /api to a running `vitrine serve` (VITRINE_SERVE, default http://127.0.0.1:8420). The
// server refuses requests whose Origin is not its own page, so the proxy drops the Origin header.
const target = process.env.VITRINE_SERVE ?? 'http://127.0.0.1:8420';

export default defineConfig({
  plugins: [react()],
  base: './',
  build: { outDir: 'dist', emptyOutDir: true, chunkSizeWarningLimit: 600 },
  server: {
    proxy: {
      '/api': {
        target,
        changeOrigin: true,
        configure: (proxy) => {
          proxy.on('proxyReq', (req) => req.removeHeader('origin'));
        },
      },
    },
  },
});
