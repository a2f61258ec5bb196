#include "core/image/io.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "core/image/io_detail.hpp"

#include <ImfChannelList.h>
#include <ImfChromaticities.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <half.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <functional>
#include <map>
#include <set>

namespace vitrine {

namespace {

// A layer is everything before the last dot of a channel name ("diffuse.R" → "diffuse"), as in
// OpenEXR's ChannelList::layers; channels without a dot form the unnamed layer "".
std::string layerOf(const std::string& channel) {
    const size_t dot = channel.rfind('.');
    return dot == std::string::npos ? std::string() : channel.substr(0, dot);
}

std::string lowerSuffixOf(const std::string& channel) {
    std::string suffix = channel.substr(channel.rfind('.') + 1); // npos + 1 == 0
    std::transform(suffix.begin(), suffix.end(), suffix.begin(), [](unsigned char c) { return std::tolower(c); });
    return suffix;
}

// Unnamed layer first, then the others in channel (alphabetical) order.
std::vector<std::string> layersOf(const std::vector<std::string>& channels) {
    std::vector<std::string> layers;
    for (const std::string& channel : channels) {
        const std::string layer = layerOf(channel);
        if (std::find(layers.begin(), layers.end(), layer) == layers.end()) layers.push_back(layer);
    }
    std::stable_partition(layers.begin(), layers.end(), [](const std::string& layer) { return layer.empty(); });
    return layers;
}

std::string layerList(const std::vector<std::string>& layers) {
    std::string text;
    for (const std::string& layer : layers)
        text += (text.empty() ? "'" : ", '") + layer + "'";
    return text;
}

// Runs OpenEXR calls, turning their exceptions (bad files, I/O errors) into a UserError naming the file.
template <typename Function>
auto withExrErrors(const std::filesystem::path& path, const char* doing, Function&& function) {
    try {
        return function();
    } catch (const UserError&) {
        throw;
    } catch (const InternalError&) {
        throw;
    } catch (const std::exception& e) {
        throw UserError(path.string() + ": " + doing + ": " + e.what());
    }
}

struct ExrChannels {
    int width = 0;
    int height = 0;
    std::vector<std::string> layers;                  // the layers read, in the order the selector gave them
    std::map<std::string, std::vector<float>> planes; // channel name → width * height floats
};

// Given the names of all channels in the file, returns the layers to read.
using LayerSelector = std::function<std::vector<std::string>(const std::vector<std::string>& channels)>;

// Reads the chosen layers' channels as float planes; OpenEXR converts half and uint to float.
ExrChannels readChannels(const std::filesystem::path& path, const LayerSelector& select) {
    detail::requireFile(path);
    return withExrErrors(path, "cannot read OpenEXR file", [&] {
        Imf::InputFile file(path.string().c_str());
        const Imath::Box2i window = file.header().dataWindow();
        ExrChannels result;
        result.width = window.max.x - window.min.x + 1;
        result.height = window.max.y - window.min.y + 1;

        std::vector<std::string> names;
        for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
            if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
                throw UserError(path.string() + ": channel '" + it.name() +
                                "' is subsampled; expected full-resolution channels");
            names.emplace_back(it.name());
        }
        result.layers = select(names);

        Imf::FrameBuffer frameBuffer;
        const size_t pixelCount = static_cast<size_t>(result.width) * result.height;
        for (const std::string& name : names) {
            if (std::find(result.layers.begin(), result.layers.end(), layerOf(name)) == result.layers.end()) continue;
            std::vector<float>& plane = result.planes[name];
            plane.resize(pixelCount);
            frameBuffer.insert(
                name, Imf::Slice::Make(Imf::FLOAT, plane.data(), window, sizeof(float), sizeof(float) * result.width));
        }
        file.setFrameBuffer(frameBuffer);
        if (!file.isComplete())
            throw UserError(path.string() + ": the file is truncated (some scan lines are missing)");
        file.readPixels(window.min.y, window.max.y);
        return result;
    });
}

// Maps a layer's channels to RGBA: R/G/B/A, else a lone channel (luminance "Y", depth "Z", a mask)
// as grey, else X/Y/Z as a vector. Missing colour channels are 0, a missing alpha is 1.
Image assembleLayer(const std::filesystem::path& path, const ExrChannels& channels, const std::string& layer) {
    std::map<std::string, const std::vector<float>*> bySuffix;
    for (const auto& [name, plane] : channels.planes)
        if (layerOf(name) == layer) bySuffix[lowerSuffixOf(name)] = &plane;
    auto find = [&](std::initializer_list<const char*> suffixes) -> const std::vector<float>* {
        for (const char* suffix : suffixes)
            if (auto it = bySuffix.find(suffix); it != bySuffix.end()) return it->second;
        return nullptr;
    };
    const std::vector<float>* r = find({"r", "red"});
    const std::vector<float>* g = find({"g", "green"});
    const std::vector<float>* b = find({"b", "blue"});
    const std::vector<float>* a = find({"a", "alpha"});
    const std::vector<float>* x = find({"x"});
    const std::vector<float>* y = find({"y"});
    const std::vector<float>* z = find({"z"});

    std::vector<const std::vector<float>*> colour; // every channel but alpha
    for (const auto& [suffix, plane] : bySuffix)
        if (suffix != "a" && suffix != "alpha") colour.push_back(plane);
    const bool onlyXyz = std::all_of(bySuffix.begin(), bySuffix.end(), [](const auto& entry) {
        return entry.first == "x" || entry.first == "y" || entry.first == "z" || entry.first == "a" ||
               entry.first == "alpha";
    });

    std::array<const std::vector<float>*, 3> rgb{};
    if (r || g || b) {
        rgb = {r, g, b};
    } else if (colour.size() == 1) {
        rgb = {colour[0], colour[0], colour[0]};
    } else if (colour.empty() && a) {
        rgb = {a, a, a};
    } else if (onlyXyz) {
        rgb = {x, y, z};
    } else {
        std::string names;
        for (const auto& [suffix, plane] : bySuffix)
            names += (names.empty() ? "" : ", ") + suffix;
        throw UserError(path.string() + ": layer '" + layer + "' has channels " + names +
                        "; expected R,G,B[,A], X,Y,Z[,A] or a single channel such as Y or Z");
    }

    Image image(channels.width, channels.height);
    const size_t pixelCount = static_cast<size_t>(image.width) * image.height;
    for (size_t i = 0; i < pixelCount; ++i) {
        float* pixel = &image.pixels[i * 4];
        for (int c = 0; c < 3; ++c)
            pixel[c] = rgb[c] ? (*rgb[c])[i] : 0.0f;
        pixel[3] = a ? (*a)[i] : 1.0f;
    }
    return image;
}

bool hasColorChannels(const std::vector<std::string>& channels, const std::string& layer, bool acceptGrey) {
    return std::any_of(channels.begin(), channels.end(), [&](const std::string& channel) {
        const std::string suffix = lowerSuffixOf(channel);
        return layerOf(channel) == layer && (suffix == "r" || suffix == "g" || suffix == "b" || suffix == "red" ||
                                             suffix == "green" || suffix == "blue" || (acceptGrey && suffix == "y"));
    });
}

} // namespace

Image detail::loadExrDefaultLayer(const std::filesystem::path& path) {
    ExrChannels channels = readChannels(path, [&](const std::vector<std::string>& names) {
        const std::vector<std::string> layers = layersOf(names);
        if (hasColorChannels(names, "", true)) return std::vector<std::string>{""};
        for (const std::string& layer : layers)
            if (hasColorChannels(names, layer, false)) return std::vector<std::string>{layer};
        if (layers.size() == 1) return layers;
        throw UserError(path.string() + ": no layer has R, G or B channels (layers: " + layerList(layers) +
                        "); name the layer to load");
    });
    return assembleLayer(path, channels, channels.layers.front());
}

Image loadExrLayer(const std::filesystem::path& path, const std::string& layer) {
    ExrChannels channels = readChannels(path, [&](const std::vector<std::string>& names) {
        const std::vector<std::string> layers = layersOf(names);
        if (std::find(layers.begin(), layers.end(), layer) == layers.end())
            throw UserError(path.string() + ": no layer '" + layer + "'; expected one of " + layerList(layers));
        return std::vector<std::string>{layer};
    });
    return assembleLayer(path, channels, layer);
}

std::vector<std::pair<std::string, Image>> readExrLayers(const std::filesystem::path& path) {
    ExrChannels channels = readChannels(path, [](const std::vector<std::string>& names) { return layersOf(names); });
    std::vector<std::pair<std::string, Image>> layers;
    for (const std::string& layer : channels.layers)
        layers.emplace_back(layer, assembleLayer(path, channels, layer));
    return layers;
}

void writeExr(const std::filesystem::path& path, const std::vector<ExrLayer>& layers, ExrPixelType type) {
    if (layers.empty()) throw InternalError("writeExr: no layers to write to " + path.string());
    std::set<std::string> names;
    for (const ExrLayer& layer : layers) {
        if (!layer.image || layer.image->empty())
            throw InternalError("writeExr: layer '" + layer.name + "' of " + path.string() + " has no pixels");
        const Image& first = *layers.front().image;
        if (layer.image->width != first.width || layer.image->height != first.height)
            throw UserError(path.string() + ": layer '" + layer.name + "' is " + std::to_string(layer.image->width) +
                            "x" + std::to_string(layer.image->height) + " but layer '" + layers.front().name + "' is " +
                            std::to_string(first.width) + "x" + std::to_string(first.height) +
                            "; expected all layers of one EXR file to have the same size");
        if (!names.insert(layer.name).second)
            throw UserError(path.string() + ": two layers are named '" + layer.name + "'; expected unique names");
    }
    detail::requireParentDirectory(path);

    const int width = layers.front().image->width;
    const int height = layers.front().image->height;
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::addChromaticities(header, Imf::Chromaticities()); // default-constructed: Rec.709 primaries, D65
    Imf::FrameBuffer frameBuffer;
    // OpenEXR converts pixel types when reading but not when writing: half needs its own buffers.
    std::vector<std::vector<half>> halfPixels;
    for (const ExrLayer& layer : layers) {
        const std::string prefix = layer.name.empty() ? "" : layer.name + ".";
        const std::vector<float>& pixels = layer.image->pixels;
        char* base = nullptr;
        size_t sampleSize = sizeof(float);
        if (type == ExrPixelType::Half) {
            base = reinterpret_cast<char*>(halfPixels.emplace_back(pixels.begin(), pixels.end()).data());
            sampleSize = sizeof(half);
        } else {
            // OpenEXR's Slice wants a mutable pointer, but an output file only reads through it.
            base = reinterpret_cast<char*>(const_cast<float*>(pixels.data()));
        }
        const Imf::PixelType pixelType = type == ExrPixelType::Half ? Imf::HALF : Imf::FLOAT;
        for (int c = 0; c < 4; ++c) {
            const std::string channel = prefix + "RGBA"[c];
            header.channels().insert(channel, Imf::Channel(pixelType));
            frameBuffer.insert(channel,
                               Imf::Slice(pixelType, base + c * sampleSize, 4 * sampleSize, 4 * sampleSize * width));
        }
    }
    writeFileAtomically(path, [&](const std::filesystem::path& temporary) {
        withExrErrors(temporary, "cannot write OpenEXR file", [&] {
            Imf::OutputFile file(temporary.string().c_str(), header);
            file.setFrameBuffer(frameBuffer);
            file.writePixels(height);
        });
    });
}

} // namespace vitrine
