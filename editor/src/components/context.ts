import { createContext, useContext, useSyncExternalStore } from 'react';
import type { Preview, PreviewStore, Progress } from '../previews';

export interface EditorCallbacks {
  openViewer(key: string): void;
}

export const PreviewContext = createContext<PreviewStore | null>(null);
export const EditorContext = createContext<EditorCallbacks>({ openViewer: () => undefined });

export function usePreview(key: string): Preview | undefined {
  const store = useContext(PreviewContext);
  return useSyncExternalStore(store ? store.subscribe : () => () => undefined, () => store?.get(key));
}

export function useProgress(node: string): Progress | undefined {
  const store = useContext(PreviewContext);
  return useSyncExternalStore(store ? store.subscribe : () => () => undefined, () => store?.progressOf(node));
}
