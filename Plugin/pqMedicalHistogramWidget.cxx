// SPDX-License-Identifier: BSD-3-Clause
#include "pqMedicalHistogramWidget.h"

#include "vtkSMMedicalIsosurfaceInitializationHelper.h"
#include "vtkSMSourceProxy.h"

#include <QFontMetrics>
#include <QHelpEvent>
#include <QKeyEvent>
#include <QLocale>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>
#include <QPalette>
#include <QStringList>
#include <QToolTip>

#include <algorithm>
#include <cmath>

namespace
{
// How far (logical pixels) from a marker a press still grabs it.
constexpr double GrabDistance = 6.0;
// The marker's handle: a triangle this wide at the top of its line.
constexpr double HandleWidth = 9.0;

QString FormatNumber(double value)
{
  return QString::number(value, 'g', 8);
}

// `over` laid on `under` with weight t: the bars in a tone of the palette's
// text, readable on light and dark themes alike.
QColor Blend(const QColor& under, const QColor& over, double t)
{
  return QColor::fromRgbF(under.redF() + t * (over.redF() - under.redF()),
    under.greenF() + t * (over.greenF() - under.greenF()),
    under.blueF() + t * (over.blueF() - under.blueF()));
}
}

//------------------------------------------------------------------------------
pqMedicalHistogramWidget::pqMedicalHistogramWidget(QWidget* parentObject)
  : Superclass(parentObject)
{
  this->setObjectName("Histogram");
  this->setMouseTracking(true);
  this->setFocusPolicy(Qt::ClickFocus);
  this->setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Fixed);
}

//------------------------------------------------------------------------------
pqMedicalHistogramWidget::~pqMedicalHistogramWidget() = default;

//------------------------------------------------------------------------------
QSize pqMedicalHistogramWidget::sizeHint() const
{
  return QSize(240, 64 + this->fontMetrics().height());
}

//------------------------------------------------------------------------------
QSize pqMedicalHistogramWidget::minimumSizeHint() const
{
  return QSize(120, this->sizeHint().height());
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::gatherHistogram(
  vtkSMSourceProxy* source, unsigned int port, const char* arrayName)
{
  double range[2];
  bool integral = false;
  double low = 0.0;
  double width = 1.0;
  std::vector<double> counts;
  if (!source ||
    !vtkSMMedicalIsosurfaceInitializationHelper::GatherHistogram(
      source, port, arrayName, range, integral, low, width, counts))
  {
    this->clearHistogram();
    return;
  }
  this->setHistogram(range, low, width, counts, integral);
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::setHistogram(
  const double range[2], double low, double width, const std::vector<double>& counts, bool integral)
{
  this->Range[0] = range[0];
  this->Range[1] = range[1];
  this->Low = low;
  this->Width = width > 0.0 ? width : 1.0;
  this->Counts = counts;
  this->Integral = integral;
  this->update();
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::clearHistogram()
{
  this->Counts.clear();
  this->Range[0] = 0.0;
  this->Range[1] = 1.0;
  this->update();
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::setMarkers(
  const std::vector<double>& values, const std::vector<QColor>& colors)
{
  const bool dragging = this->Dragged >= 0 && this->Dragged < static_cast<int>(values.size()) &&
    values.size() == this->Values.size();
  const double dragged = dragging ? this->Values[static_cast<std::size_t>(this->Dragged)] : 0.0;
  if (!dragging && this->Dragged >= 0)
  {
    // The rows changed under the drag (a script, an undo): the drag is over.
    this->Dragged = -1;
  }
  this->Values = values;
  this->Colors = colors;
  if (dragging)
  {
    this->Values[static_cast<std::size_t>(this->Dragged)] = dragged;
  }
  this->update();
}

//------------------------------------------------------------------------------
QString pqMedicalHistogramWidget::markerValues() const
{
  QStringList list;
  for (double value : this->Values)
  {
    list << FormatNumber(value);
  }
  return list.join(',');
}

//------------------------------------------------------------------------------
QRectF pqMedicalHistogramWidget::plotRect() const
{
  const double labels = this->fontMetrics().height() + 2.0;
  // Half a handle each side, so a marker at either end of the range shows whole.
  const double side = 0.5 * HandleWidth + 1.0;
  return QRectF(side, 1.0, std::max(1.0, this->width() - 2.0 * side),
    std::max(1.0, this->height() - labels - 1.0));
}

//------------------------------------------------------------------------------
double pqMedicalHistogramWidget::xOf(double value) const
{
  const QRectF plot = this->plotRect();
  const double span = this->Range[1] - this->Range[0];
  if (!(span > 0.0))
  {
    return plot.center().x();
  }
  return plot.left() + (value - this->Range[0]) / span * plot.width();
}

//------------------------------------------------------------------------------
double pqMedicalHistogramWidget::valueAt(int x) const
{
  const QRectF plot = this->plotRect();
  const double span = this->Range[1] - this->Range[0];
  if (!(span > 0.0))
  {
    return this->Range[0];
  }
  const double t = std::min(1.0, std::max(0.0, (x - plot.left()) / plot.width()));
  double value = this->Range[0] + t * span;
  // Round to what one pixel resolves (a power of ten), integers for integer data.
  double step = std::pow(10.0, std::floor(std::log10(span / plot.width())));
  if (this->Integral)
  {
    step = std::max(1.0, step);
  }
  value = std::round(value / step) * step;
  return std::min(this->Range[1], std::max(this->Range[0], value));
}

//------------------------------------------------------------------------------
int pqMedicalHistogramWidget::markerNear(double x) const
{
  const QRectF plot = this->plotRect();
  int nearest = -1;
  double best = GrabDistance;
  for (std::size_t i = 0; i < this->Values.size(); ++i)
  {
    // A value outside the range is drawn (and grabbed) at that end.
    const double at = std::min(plot.right(), std::max(plot.left(), this->xOf(this->Values[i])));
    const double distance = std::abs(at - x);
    if (std::isfinite(this->Values[i]) && distance <= best)
    {
      best = distance;
      nearest = static_cast<int>(i);
    }
  }
  return nearest;
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::paintEvent(QPaintEvent*)
{
  QPainter painter(this);
  painter.setRenderHint(QPainter::Antialiasing, true);
  const QPalette& colors = this->palette();
  const QRectF plot = this->plotRect();

  painter.fillRect(plot, colors.color(QPalette::Base));
  painter.setPen(QPen(colors.color(QPalette::Mid), 1.0));
  painter.drawRect(plot.adjusted(-0.5, -0.5, 0.5, 0.5));

  const QColor text = colors.color(QPalette::Text);
  if (this->Counts.empty())
  {
    painter.setPen(colors.color(QPalette::Disabled, QPalette::Text));
    painter.drawText(
      plot, Qt::AlignCenter | Qt::TextWordWrap, tr("No histogram: no one-component point array"));
    return;
  }

  // Bars: log(1 + count) of the fullest bin fills the height.
  const double fullest = *std::max_element(this->Counts.begin(), this->Counts.end());
  const double scale = fullest > 0.0 ? plot.height() / std::log1p(fullest) : 0.0;
  QPainterPath bars;
  bars.moveTo(plot.left(), plot.bottom());
  for (std::size_t i = 0; i < this->Counts.size(); ++i)
  {
    const double x0 = std::max(plot.left(), this->xOf(this->Low + i * this->Width));
    const double x1 = std::min(plot.right(), this->xOf(this->Low + (i + 1) * this->Width));
    const double top = plot.bottom() - scale * std::log1p(this->Counts[i]);
    bars.lineTo(x0, top);
    bars.lineTo(x1, top);
  }
  bars.lineTo(plot.right(), plot.bottom());
  bars.closeSubpath();
  painter.save();
  painter.setClipRect(plot);
  painter.setPen(Qt::NoPen);
  painter.setBrush(Blend(colors.color(QPalette::Base), text, 0.35));
  painter.drawPath(bars);
  painter.restore();

  // The range on the axis.
  painter.setPen(text);
  const QRectF labels(
    0.0, plot.bottom() + 1.0, this->width(), this->height() - plot.bottom() - 1.0);
  painter.drawText(labels, Qt::AlignLeft | Qt::AlignVCenter, FormatNumber(this->Range[0]));
  painter.drawText(labels, Qt::AlignRight | Qt::AlignVCenter, FormatNumber(this->Range[1]));

  // Markers: the colour over an outline that contrasts with it.
  for (std::size_t i = 0; i < this->Values.size(); ++i)
  {
    const double value = this->Values[i];
    if (!std::isfinite(value))
    {
      continue;
    }
    const QColor color =
      i < this->Colors.size() && this->Colors[i].isValid() ? this->Colors[i] : text;
    const QColor outline =
      color.lightnessF() > 0.5 ? QColor(0, 0, 0, 190) : QColor(255, 255, 255, 210);
    const bool outside = value < this->Range[0] || value > this->Range[1];
    const double x = std::min(plot.right(), std::max(plot.left(), this->xOf(value)));
    const bool dragged = static_cast<int>(i) == this->Dragged;
    painter.setPen(
      QPen(outline, dragged ? 4.0 : 3.0, outside ? Qt::DashLine : Qt::SolidLine, Qt::FlatCap));
    painter.drawLine(QPointF(x, plot.top() + 4.0), QPointF(x, plot.bottom()));
    painter.setPen(
      QPen(color, dragged ? 2.5 : 1.5, outside ? Qt::DashLine : Qt::SolidLine, Qt::FlatCap));
    painter.drawLine(QPointF(x, plot.top() + 4.0), QPointF(x, plot.bottom()));
    // The handle: pointing down inside the range, outward at an end it is past.
    QPolygonF handle;
    const double h = 0.5 * HandleWidth;
    if (!outside)
    {
      handle << QPointF(x - h, plot.top()) << QPointF(x + h, plot.top())
             << QPointF(x, plot.top() + HandleWidth);
    }
    else
    {
      const double out = value < this->Range[0] ? -1.0 : 1.0;
      handle << QPointF(x - out * h, plot.top()) << QPointF(x - out * h, plot.top() + HandleWidth)
             << QPointF(x + out * h, plot.top() + h);
    }
    painter.setPen(QPen(outline, 1.0));
    painter.setBrush(color);
    painter.drawPolygon(handle);
    if (dragged)
    {
      // The value next to the line, on the side with room.
      const QString label = FormatNumber(value);
      const double w = this->fontMetrics().horizontalAdvance(label) + 6.0;
      const double left = x + w + 4.0 < plot.right() ? x + 4.0 : x - w - 4.0;
      const QRectF box(left, plot.top() + HandleWidth + 2.0, w, this->fontMetrics().height());
      painter.setPen(Qt::NoPen);
      painter.setBrush(QColor(colors.color(QPalette::Base).red(),
        colors.color(QPalette::Base).green(), colors.color(QPalette::Base).blue(), 220));
      painter.drawRect(box);
      painter.setPen(text);
      painter.drawText(box, Qt::AlignCenter, label);
    }
  }
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::mousePressEvent(QMouseEvent* event)
{
  if (this->Dragged >= 0)
  {
    // Another button during a drag: abandon it.
    this->cancelDrag();
    event->accept();
    return;
  }
  const int marker = event->button() == Qt::LeftButton && !this->Counts.empty()
    ? this->markerNear(event->pos().x())
    : -1;
  if (marker < 0)
  {
    Superclass::mousePressEvent(event);
    return;
  }
  this->Dragged = marker;
  this->DragStart = this->Values[static_cast<std::size_t>(marker)];
  this->DragMoved = false;
  this->setFocus(Qt::MouseFocusReason);
  this->update();
  event->accept();
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::mouseMoveEvent(QMouseEvent* event)
{
  if (this->Dragged < 0 || !(event->buttons() & Qt::LeftButton))
  {
    // Hovering: say which markers can be dragged.
    const bool over = !this->Counts.empty() && this->markerNear(event->pos().x()) >= 0;
    if (over)
    {
      this->setCursor(Qt::SizeHorCursor);
    }
    else
    {
      this->unsetCursor();
    }
    Superclass::mouseMoveEvent(event);
    return;
  }
  const double value = this->valueAt(event->pos().x());
  double& current = this->Values[static_cast<std::size_t>(this->Dragged)];
  if (value != current)
  {
    current = value;
    this->DragMoved = true;
    this->update();
    Q_EMIT this->markerMoved(this->Dragged, value);
  }
  event->accept();
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::mouseReleaseEvent(QMouseEvent* event)
{
  if (this->Dragged < 0 || event->button() != Qt::LeftButton)
  {
    Superclass::mouseReleaseEvent(event);
    return;
  }
  const int marker = this->Dragged;
  const double value = this->Values[static_cast<std::size_t>(marker)];
  this->Dragged = -1;
  this->update();
  event->accept();
  if (value != this->DragStart)
  {
    Q_EMIT this->markerReleased(marker, value);
  }
  else if (this->DragMoved)
  {
    // Moved and brought back: the previews end where they began.
    Q_EMIT this->markerCancelled(marker, value);
  }
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::keyPressEvent(QKeyEvent* event)
{
  if (this->Dragged >= 0 && event->key() == Qt::Key_Escape)
  {
    this->cancelDrag();
    event->accept();
    return;
  }
  Superclass::keyPressEvent(event);
}

//------------------------------------------------------------------------------
void pqMedicalHistogramWidget::cancelDrag()
{
  const int marker = this->Dragged;
  if (marker < 0)
  {
    return;
  }
  this->Values[static_cast<std::size_t>(marker)] = this->DragStart;
  this->Dragged = -1;
  this->update();
  if (this->DragMoved)
  {
    Q_EMIT this->markerCancelled(marker, this->DragStart);
  }
}

//------------------------------------------------------------------------------
bool pqMedicalHistogramWidget::event(QEvent* e)
{
  if (e->type() != QEvent::ToolTip)
  {
    return Superclass::event(e);
  }
  auto* help = static_cast<QHelpEvent*>(e);
  QString tip;
  if (this->Counts.empty())
  {
    tip = tr("The histogram of the array the surfaces are drawn from appears here when it has "
             "one component.");
  }
  else if (const int marker = this->markerNear(help->pos().x()); marker >= 0)
  {
    const double value = this->Values[static_cast<std::size_t>(marker)];
    tip = tr("Isosurface %1: %2. Drag to change it; Esc cancels the drag.")
            .arg(marker + 1)
            .arg(FormatNumber(value));
    if (value < this->Range[0] || value > this->Range[1])
    {
      tip += QLatin1Char(' ') + tr("Outside the data range: nothing is drawn.");
    }
  }
  else if (this->plotRect().contains(help->pos()))
  {
    const double value = this->valueAt(help->pos().x());
    const double at = std::floor((value - this->Low) / this->Width);
    const auto bin = static_cast<std::size_t>(
      std::min(static_cast<double>(this->Counts.size() - 1), std::max(0.0, at)));
    const double low = this->Low + bin * this->Width;
    tip = tr("Values %1 to %2: %3 points (bars on a log scale). Drag a marker to move an "
             "isovalue.")
            .arg(FormatNumber(std::max(low, this->Range[0])))
            .arg(FormatNumber(std::min(low + this->Width, this->Range[1])))
            .arg(QLocale().toString(static_cast<qulonglong>(this->Counts[bin])));
  }
  else
  {
    tip = tr("The data range of the array the surfaces are drawn from.");
  }
  QToolTip::showText(help->globalPos(), tip, this);
  return true;
}
